#!/usr/bin/env python3
"""Regenerates every results table in the docs from the results JSON, between marker
comments (never typed by hand):

  docs/results.md          results:machine, results:phases, results:speedups,
                           results:allocations, results:solvers, results:scaling
  README.md                headline, chapter-map, viewer-fps (from results/viewer.json)
  chapters/NN_*/README.md  bench-table:<chapter>, and results:solvers where present

    .venv/bin/python scripts/update_docs.py                  # from results/bench.json
    .venv/bin/python scripts/update_docs.py --images docs/images   # also copy the plots
"""
import argparse
import pathlib
import re
import shutil
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from results_common import (ALL_PHASES, BASELINE, PHASE_LABELS, PHASES, POSTER_SOLVE_MS,  # noqa: E402
                            POSTER_SPEEDUPS, ResultsError, chapter_dir, die, load_checked)


def ms(x):
    return f"{x:.3f}" if x < 10 else f"{x:.2f}" if x < 100 else f"{x:.1f}"


def ratio(a, b):
    return f"x{a / b:.2f}" if b > 0 else "-"


def table(header, rows, align=None):
    align = align or ["---"] + ["---:"] * (len(header) - 1)
    lines = ["| " + " | ".join(header) + " |", "| " + " | ".join(align) + " |"]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(lines) + "\n"


def chapters_by_name(data):
    return {c["chapter"]: c for c in data["chapters"]}


def machine_table(data):
    b, m, mesh = data["build"], data["machine"], data["mesh"]
    rows = [("CPU", f"{m['cpu']} ({m.get('threads', '?')} threads)"),
            ("compiler", b["compiler"]), ("flags", f"`{b['flags']}`"),
            ("build type", b["build_type"]), ("Eigen", b["eigen"]), ("commit", data["commit"]),
            ("mesh", f"{mesh['file']}: {mesh['nodes']} nodes, {mesh['tets']} tets"),
            ("scene", data["scene"]),
            ("steps", f"{data['warmup_steps']} warm-up + {data['steps']} measured, dt = {data['dt']:g} s"),
            ("CG", f"relative tolerance {data['cg_tolerance']:g}, at most {data['cg_max_iterations']} iterations")]
    if "material" in data:
        mat = data["material"]
        rows.append(("material", f"E = {mat['E']:g} Pa, nu = {mat['nu']:g}, rho = {mat['rho']:g} kg/m^3, "
                                 f"Rayleigh alpha = {mat['alpha']:g} 1/s, beta = {mat['beta']:g} s"))
    return table(["", "measured with"], rows, ["---", "---"])


def phases_table(data):
    rows = []
    for c in data["chapters"]:
        cells = [f"{ms(c['median_ms'][p])} [{ms(c['q1_ms'][p])}, {ms(c['q3_ms'][p])}]"
                 for p in ALL_PHASES]
        rows.append([f"`{c['chapter']}`"] + cells + [f"{c['cg_iterations']:g}"])
    return table(["chapter"] + [PHASE_LABELS[p] for p in ALL_PHASES] + ["CG iterations"], rows)


def speedups_table(data):
    by = chapters_by_name(data)
    base = by.get(BASELINE)
    if base is None:
        return f"(no {BASELINE} in the results: no speedups)\n"
    rows = []
    for c in data["chapters"]:
        rows.append([f"`{c['chapter']}`"] +
                    [ratio(base["median_ms"][p], c["median_ms"][p]) for p in PHASES])
    rows.append(["**poster** (optimized vs naive)"] +
                [f"x{POSTER_SPEEDUPS[p]:g}" if p in POSTER_SPEEDUPS else "-" for p in PHASES])
    return table(["chapter"] + [PHASE_LABELS[p] for p in PHASES], rows)


def allocations_table(data):
    rows = []
    for c in data["chapters"]:
        per_phase = c.get("allocations", {})
        rows.append([f"`{c['chapter']}`", f"{c['allocations_per_step']:g}"] +
                    [str(per_phase.get(p, "-")) for p in ALL_PHASES if p != "step"])
    return table(["chapter", "per step"] + [PHASE_LABELS[p] for p in ALL_PHASES if p != "step"], rows)


def solvers_table(data):
    solvers = data.get("solvers")
    if not solvers:
        return "(the benchmark ran with --no-solvers)\n"
    base = solvers[0]["median_ms"]
    rows = []
    for s in solvers:
        poster = POSTER_SOLVE_MS.get(s["name"])
        rows.append([f"`{s['name']}`", ms(s["median_ms"]), ratio(base, s["median_ms"]),
                     f"{s['iterations']:g}", f"{s['allocations_per_solve']:g}",
                     f"{poster:g} ms (x{POSTER_SOLVE_MS['eigen_cg'] / poster:.3g})" if poster else "-"])
    return table(["solver", "median ms", f"vs `{solvers[0]['name']}`", "iterations",
                  "allocations per solve", "poster"], rows)


def scaling_table(scaling):
    if scaling is None:
        return "(run `./tutorial.sh scaling` to fill this table)\n"
    sizes = sorted({r["nodes"] for r in scaling["runs"]})
    chapters = sorted({r["chapter"] for r in scaling["runs"]})
    step = {(r["chapter"], r["nodes"]): r["step_ms"] for r in scaling["runs"]}
    rows = [[f"`{c}`"] + [ms(step[(c, n)]) if (c, n) in step else "stopped" for n in sizes]
            for c in chapters]
    return table(["median step ms / nodes"] + [str(n) for n in sizes], rows)


def viewer_table(viewer):
    """The viewer's frame rate per chapter (results/viewer.json, from scripts/viewer_fps.py)."""
    runs = viewer["runs"]
    rows = [["drawing only (`--paused`)" if r["run"] == "paused" else f"`{r['chapter']}`",
             f"{r['frames_per_second']:.1f}", ms(r["mean_step_ms"]) if r["run"] != "paused" else "-"]
            for r in runs]
    first = runs[0]
    mesh = pathlib.Path(first["mesh"]).name
    return (table(["chapter", "frames/s", "mean step (ms)"], rows) +
            f"\nMeasured by `./tutorial.sh viewer-bench`: {mesh} ({first['nodes']} nodes), "
            f"{first['width']}x{first['height']}, {viewer['frames']} frames a run, one step per frame, "
            f"renderer {first['renderer']}, {first['cpu']}, {first['compiler']} `{first['flags']}`, "
            f"commit {viewer['commit']}.\n")


def headline(data):
    by = chapters_by_name(data)
    base = by.get(BASELINE)
    rows = []
    for c in data["chapters"]:
        rows.append([f"[`{c['chapter']}`](chapters/{chapter_dir(c['chapter'])}/README.md)", ms(c["median_ms"]["step"]),
                     ratio(base["median_ms"]["step"], c["median_ms"]["step"]) if base else "-",
                     f"{c['allocations_per_step']:g}"])
    mesh, b = data["mesh"], data["build"]
    return ("![Speedup per phase over chapter 01, beside the poster's](docs/images/speedup.png)\n\n" +
            table(["chapter", "step (ms, median)", "speedup over 01", "allocations per step"], rows) +
            f"\nMeasured by `./tutorial.sh bench` on {mesh['file']} ({mesh['nodes']} nodes, "
            f"{mesh['tets']} tets), {data['scene']} scene, {data['machine']['cpu']}, "
            f"{b['compiler']} `{b['flags']}`, commit {data['commit']}.\n")


def chapter_map(data):
    """One line per chapter: the idea, the phase it moves most, the overall step speedup."""
    by = chapters_by_name(data)
    base = by.get(BASELINE)
    rows, previous = [], None
    for c in data["chapters"]:
        name = c["chapter"]
        moved = "the baseline"
        if previous is not None and c["median_ms"]["dfdx"] == 0 < previous["median_ms"]["dfdx"]:
            # A fused element pass (chapter 08) has no df/dx phase of its own: compare the three
            # phases it replaces together, not a zero.
            fused = ("forces", "dfdx", "compose")
            moved = (f"forces + df/dx + composition (fused) "
                     f"{ratio(sum(previous['median_ms'][p] for p in fused), sum(c['median_ms'][p] for p in fused))} "
                     f"over `{previous['chapter']}`")
        elif previous is not None:
            phase = max(PHASES[:-1], key=lambda p: previous["median_ms"][p] / max(c["median_ms"][p], 1e-9))
            moved = (f"{PHASE_LABELS[phase]} {ratio(previous['median_ms'][phase], c['median_ms'][phase])} "
                     f"over `{previous['chapter']}`")
        diff = f"[diff](docs/diffs/{chapter_dir(name)}.diff)" if previous is not None and \
            chapter_dir(previous["chapter"]) != chapter_dir(name) else ""
        rows.append([f"[`{name}`](chapters/{chapter_dir(name)}/README.md)", c.get("title", ""), moved,
                     ratio(base["median_ms"]["step"], c["median_ms"]["step"]) if base else "-", diff])
        previous = c
    return table(["chapter", "the idea", "the phase it moves most", "step speedup over 01", "diff"],
                 rows, ["---", "---", "---", "---:", "---"])


def chapter_table(data, name):
    by = chapters_by_name(data)
    c = by[name]
    names = [x["chapter"] for x in data["chapters"]]
    previous = by.get(names[names.index(name) - 1]) if names.index(name) > 0 else None
    shown = [x for x in (by.get(BASELINE), previous, c) if x is not None]
    shown = [x for i, x in enumerate(shown) if x not in shown[:i]]
    rows = [[f"`{x['chapter']}`"] + [ms(x["median_ms"][p]) for p in ALL_PHASES] +
            [f"{x['allocations_per_step']:g}", f"{x['cg_iterations']:g}"] for x in shown]
    for ref in (by.get(BASELINE), previous):
        if ref is not None and ref is not c:
            rows.append([f"speedup over `{ref['chapter']}`"] +
                        [ratio(ref["median_ms"][p], c["median_ms"][p]) for p in ALL_PHASES] + ["", ""])
    header = ["median ms"] + [PHASE_LABELS[p] for p in ALL_PHASES] + ["allocations/step", "CG it."]
    fused_note = ""
    if previous is not None and c["median_ms"]["dfdx"] == 0 < previous["median_ms"]["dfdx"]:
        # A fused element pass has no df/dx phase: the three phases it replaces, summed.
        fused = lambda x: sum(x["median_ms"][p] for p in ("forces", "dfdx", "compose"))  # noqa: E731
        fused_note = (f" Forces + df/dx construction + system composition, the work of the fused "
                      f"element pass: {ms(fused(previous))} ms in `{previous['chapter']}`, "
                      f"{ms(fused(c))} ms in `{c['chapter']}` ({ratio(fused(previous), fused(c))}).")
    return (table(header, rows) +
            f"\n{data['mesh']['file']}, {data['scene']}, {data['steps']} steps; machine and flags in "
            f"[docs/results.md](../../docs/results.md).{fused_note} Generated by `scripts/update_docs.py`.\n")


def threads_table(threads):
    """Chapter 09 per thread count (results/threads.json, from ./tutorial.sh threads): every
    phase, and the speedup of each over the same chapter on one thread."""
    rows = []
    for c in threads["chapters"]:
        one = next((x for x in threads["chapters"] if chapter_dir(x["chapter"]) == chapter_dir(c["chapter"])
                    and x.get("threads", 1) == 1), c)
        rows.append([f"`{c['chapter']}`"] + [ms(c["median_ms"][p]) for p in ALL_PHASES] +
                    [ratio(one["median_ms"]["solve"], c["median_ms"]["solve"]),
                     ratio(one["median_ms"]["step"], c["median_ms"]["step"])])
    header = (["median ms"] + [PHASE_LABELS[p] for p in ALL_PHASES] +
              ["solve vs 1 thread", "step vs 1 thread"])
    b, m = threads["build"], threads["machine"]
    return (table(header, rows) +
            f"\n{threads['mesh']['file']}, {threads['scene']}, {threads['steps']} steps, one interleaved run "
            f"(`./tutorial.sh threads`) on {m['cpu']} with {m.get('threads', '?')} hardware threads"
            + (f" (1-minute load average {m['load_average'][0]:.1f} at the start, "
               f"{m['load_average'][1]:.1f} at the end)" if "load_average" in m else "") + ", "
            f"{b['compiler']} `{b['flags']}`, commit {threads['commit']}. Generated by `scripts/update_docs.py`.\n")


def replace(text, name, body):
    """Replaces what stands between <!-- name:begin --> and <!-- name:end -->."""
    begin, end = f"<!-- {name}:begin -->", f"<!-- {name}:end -->"
    pattern = re.compile(re.escape(begin) + ".*?" + re.escape(end), re.S)
    if not pattern.search(text):
        return text, False
    return pattern.sub(lambda _: begin + "\n" + body + end, text), True


def update_file(path, sections):
    if not path.exists():
        print(f"note: {path} is missing, skipped")
        return
    text = path.read_text()
    done = []
    for name, body in sections.items():
        text, found = replace(text, name, body)
        if found:
            done.append(name)
    path.write_text(text)
    if done:
        print(f"updated {path}: {', '.join(done)}")


def main():
    root_default = pathlib.Path(__file__).resolve().parent.parent
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--root", type=pathlib.Path, default=root_default, help="repository root")
    parser.add_argument("--bench", type=pathlib.Path, help="default: ROOT/results/bench.json")
    parser.add_argument("--scaling", type=pathlib.Path, help="default: ROOT/results/scaling.json if present")
    parser.add_argument("--viewer", type=pathlib.Path, help="default: ROOT/results/viewer.json if present")
    parser.add_argument("--threads", type=pathlib.Path, help="default: ROOT/results/threads.json if present")
    parser.add_argument("--images", type=pathlib.Path, nargs="?", const=pathlib.Path("docs/images"),
                        help="copy the PNG plots from the results directory here (default docs/images)")
    args = parser.parse_args()
    root = args.root
    bench_path = args.bench or root / "results" / "bench.json"
    scaling_path = args.scaling or root / "results" / "scaling.json"
    try:
        data = load_checked(bench_path)
        scaling = load_checked(scaling_path, scaling=True) if scaling_path.exists() else None
        viewer_path = args.viewer or root / "results" / "viewer.json"
        viewer = load_checked(viewer_path, viewer=True) if viewer_path.exists() else None
        threads_path = args.threads or root / "results" / "threads.json"
        threads = load_checked(threads_path) if threads_path.exists() else None
    except ResultsError as e:
        die(f"update_docs.py: {e}")

    solvers = solvers_table(data)
    tables = {
        "results:machine": machine_table(data), "results:phases": phases_table(data),
        "results:speedups": speedups_table(data), "results:allocations": allocations_table(data),
        "results:solvers": solvers}
    # The scaling run takes tens of minutes and is optional: without results/scaling.json the
    # committed table stays as it is (a placeholder goes in only where there is no table yet).
    if scaling is not None or "run `./tutorial.sh scaling`" in (root / "docs" / "results.md").read_text():
        tables["results:scaling"] = scaling_table(scaling)
    else:
        print("no results/scaling.json: the scaling table in docs/results.md is left as it is")
    update_file(root / "docs" / "results.md", tables)
    readme = {"headline": headline(data), "chapter-map": chapter_map(data)}
    if viewer is not None:  # like the scaling table: optional, kept as it is without a new run
        readme["viewer-fps"] = viewer_table(viewer)
    update_file(root / "README.md", readme)
    for c in data["chapters"]:
        update_file(root / "chapters" / chapter_dir(c["chapter"]) / "README.md",
                    {f"bench-table:{c['chapter']}": chapter_table(data, c["chapter"]),
                     "results:solvers": solvers})
    if threads is not None:  # like the scaling table: kept as it is without a new run
        update_file(root / "chapters" / "09_threads" / "README.md",
                    {"threads-table": threads_table(threads)})
    if args.images:
        images = args.images if args.images.is_absolute() else root / args.images
        images.mkdir(parents=True, exist_ok=True)
        for png in sorted(bench_path.parent.glob("*.png")):
            shutil.copy(png, images / png.name)
            print(f"copied {png.name} to {images}")


if __name__ == "__main__":
    main()
