"""Regenerates every results table in the docs from the results JSON, between marker
comments (never typed by hand):

  docs/results.md          results:machine, results:phases, results:speedups,
                           results:allocations, results:solvers, results:scaling, and
                           viewer-fps (from results/viewer.json)
  README.md                headline, chapter-map
  regime sweep             regimes:poster, regimes:points, regimes:solvers in docs/results.md and
                           regimes:poster in README.md (from results/regimes.json, copied to
                           docs/data/regimes.json; without it, from docs/data/regimes.json)
  chapters/NN_*/README.md  bench-table:<chapter>, and results:solvers where present

The JSON behind the committed docs is committed too, in docs/data/ (bench.json, and
scaling.json and viewer.json when they were run): `./tutorial.sh docs` copies a new run there
first. --check writes nothing and fails when a generated section differs from what the
committed JSON gives (ctest label docs).

    fem-tools docs update                  # from docs/data/bench.json
    fem-tools docs update --images docs/images   # also copy the plots
    fem-tools docs update --check          # are the docs those of docs/data?
"""
import argparse
import pathlib
import re
import shutil
import sys

from femtools.results import regimes as regimes_common
from femtools.results.common import (ALL_PHASES, BASELINE, PHASE_LABELS, PHASES, POSTER_SOLVE_MS,
                            POSTER_SPEEDUPS, ResultsError, cache_summary, chapter_dir, die,
                            load_checked, machine_summary)
from femtools.results.common import load
from femtools.paths import ROOT


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
    rows = [("CPU", f"{m['cpu']} ({machine_summary(m)})"),
            ("compiler", b["compiler"]), ("flags", f"`{b['flags']}`"),
            ("build type", b["build_type"]), ("Eigen", b["eigen"]), ("commit", data["commit"]),
            ("mesh", f"{mesh['file']}: {mesh['nodes']} nodes, {mesh['tets']} tets"),
            ("scene", data["scene"]),
            ("steps", f"{data['warmup_steps']} warm-up + {data['steps']} measured, dt = {data['dt']:g} s"),
            ("CG", f"relative tolerance {data['cg_tolerance']:g}, at most {data['cg_max_iterations']} iterations")]
    if cache_summary(m):
        rows.append(("caches, memory", f"{cache_summary(m)}; {m['memory_bytes'] / 2**30:.0f} GiB"))
    if m.get("other_cpus") is not None:
        rows.append(("machine load", f"other processes used {m['other_cpus']:.2g} of {m.get('threads', '?')} "
                                     f"cores during the run" + (" (**busy**: the times are not the code's alone)"
                                                                if m.get("busy") else "")))
    if data.get("uncommitted"):
        rows.append(("uncommitted", ", ".join(f"`{f}`" for f in data["uncommitted"])))
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
        split = [ms(s[k]) if k in s else "-" for k in ("setup_ms", "solve_ms")]
        rows.append([f"`{s['name']}`", ms(s["median_ms"])] + split + [ratio(base, s["median_ms"]),
                     f"{s['iterations']:g}", f"{s['allocations_per_solve']:g}",
                     f"{poster:g} ms (x{POSTER_SOLVE_MS['eigen_cg'] / poster:.3g})" if poster else "-"])
    return table(["solver", "median ms", "setup ms", "solve ms", f"vs `{solvers[0]['name']}`",
                  "iterations", "allocations per solve", "poster"], rows)


def scaling_table(scaling):
    if scaling is None:
        return "(run `./tutorial.sh scaling` to fill this table)\n"
    sizes = sorted({r["nodes"] for r in scaling["runs"]})
    chapters = sorted({r["chapter"] for r in scaling["runs"]})
    step = {(r["chapter"], r["nodes"]): r["step_ms"] for r in scaling["runs"]}
    rows = [[f"`{c}`"] + [ms(step[(c, n)]) if (c, n) in step else "stopped" for n in sizes]
            for c in chapters]
    # The iterations say why the step grows faster than the mesh: Jacobi's count grows with
    # the resolution, multigrid's (chapter 10) should not.
    its = {(r["chapter"], r["nodes"]): r["cg_iterations"] for r in scaling["runs"]}
    it_rows = [[f"`{c}`"] + [f"{its[(c, n)]:g}" if (c, n) in its else "stopped" for n in sizes]
               for c in chapters]
    return (table(["median step ms / nodes"] + [str(n) for n in sizes], rows) + "\n" +
            table(["median CG iterations / nodes"] + [str(n) for n in sizes], it_rows))


def multigrid_scaling(scaling):
    """Chapter 10 over the beam series (docs/data/scaling.json): iterations, solve and step time
    per node from the smallest mesh to the largest, beside chapter 09's. How much more slowly
    multigrid's solve grows with the mesh than block Jacobi's, on this machine."""
    rows = []
    names = sorted({r["chapter"] for r in scaling["runs"]
                    if chapter_dir(r["chapter"]).startswith(("09_", "10_"))})
    for name in names:
        runs = sorted((r for r in scaling["runs"] if r["chapter"] == name), key=lambda r: r["nodes"])
        if len(runs) < 2:
            continue
        lo, hi = runs[0], runs[-1]
        per_node = [1e3 * r["step_ms"] / r["nodes"] for r in (lo, hi)]
        solve_per_node = [1e3 * r["solve_ms"] / r["nodes"] for r in (lo, hi)]
        rows.append([f"`{name}`", f"{lo['nodes']} to {hi['nodes']} (x{hi['nodes'] / lo['nodes']:.0f})",
                     f"{lo['cg_iterations']:g} to {hi['cg_iterations']:g}",
                     f"{ms(lo['step_ms'])} to {ms(hi['step_ms'])}",
                     f"{solve_per_node[0]:.2f} to {solve_per_node[1]:.2f} "
                     f"(x{solve_per_node[1] / solve_per_node[0]:.1f})",
                     f"{per_node[0]:.2f} to {per_node[1]:.2f} (x{per_node[1] / per_node[0]:.1f})"])
    if not rows:
        return "(no chapter 09 or 10 in docs/data/scaling.json: run `./tutorial.sh scaling`)\n"
    return (table(["chapter", "nodes, smallest to largest beam", "median CG iterations",
                   "median step (ms)", "solve per node (us)", "step per node (us)"], rows) +
            f"\nThe beam series of `./tutorial.sh scaling`, {scaling['scene']} scene, commit "
            f"{scaling['commit']}. Generated by `tools/femtools/docs/update.py` from docs/data/scaling.json.\n")


def pair_scaling(scaling, before, after):
    """Two chapters over the beam series (docs/data/scaling.json): the rest of the step (step
    minus solve: the element pass and the system's start) and the solve, at each thread count,
    with the later chapter's ratio to the earlier one. Chapter 11 against 10 (the order of
    memory), chapter 12 against 11 (half the bytes): what each measures to on this machine."""
    by = {(r["chapter"], r["mesh"]): r for r in scaling["runs"]}
    short = [c.split("_")[0] for c in (before, after)]
    rows = []
    for threads in ("1", "2"):
        first, second = f"{before}@{threads}", f"{after}@{threads}"
        meshes = sorted({r["mesh"] for r in scaling["runs"] if r["chapter"] == second},
                        key=lambda m: by[(second, m)]["nodes"])
        for mesh in meshes:
            a, b = by.get((first, mesh)), by[(second, mesh)]
            if a is None:
                continue
            rest = [x["step_ms"] - x["solve_ms"] for x in (a, b)]
            rows.append([f"`{mesh}`", f"{b['nodes']}", threads,
                         f"{ms(rest[0])} / {ms(rest[1])} ({ratio(rest[0], rest[1])})",
                         f"{ms(a['solve_ms'])} / {ms(b['solve_ms'])} ({ratio(a['solve_ms'], b['solve_ms'])})",
                         f"{ms(a['step_ms'])} / {ms(b['step_ms'])} ({ratio(a['step_ms'], b['step_ms'])})",
                         f"{a['cg_iterations']:g} / {b['cg_iterations']:g}"])
    if not rows:
        return (f"(no chapters {short[0]} and {short[1]} in docs/data/scaling.json: run "
                "`./tutorial.sh scaling`)\n")
    pair = f"{short[0]} / {short[1]}"
    return (table(["mesh", "nodes", "threads", f"step minus solve, ms: {pair} (speedup)",
                   f"solve, ms: {pair}", f"step, ms: {pair}", f"CG it.: {pair}"], rows) +
            f"\nThe beam series of `./tutorial.sh scaling`, {scaling['scene']} scene, commit "
            f"{scaling['commit']}. Generated by `tools/femtools/docs/update.py` from docs/data/scaling.json.\n")


def viewer_table(viewer):
    """The viewer's frame rate per chapter (results/viewer.json, from fem-tools runs viewer-fps)."""
    runs = viewer["runs"]
    rows = [["drawing only (`--paused`)" if r["run"] == "paused" else f"`{r['chapter']}`",
             f"{r['frames_per_second']:.1f}", ms(r["mean_step_ms"]) if r["run"] != "paused" else "-"]
            for r in runs]
    first = runs[0]
    mesh = pathlib.Path(first["mesh"]).name
    return (table(["chapter", "frames/s", "mean step (ms)"], rows) +
            f"\nMeasured by `./tutorial.sh viewer-bench`: {mesh} ({first['nodes']} nodes), "
            f"{first['width']}x{first['height']}, {viewer['frames']} frames a run, one step per frame, "
            f"renderer {first['renderer']}, {first['cpu']}"
            + (f" ({machine_summary(first['machine'])})" if "machine" in first else "") +
            f", {first['compiler']} `{first['flags']}`, "
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
    return ("![The course at a glance: each chapter's step split into its phases]"
            "(docs/images/phases_stacked.png)\n\n"
            "![Speedup per phase over chapter 01, beside the poster's](docs/images/speedup.png)\n\n" +
            table(["chapter", "step (ms, median)", "speedup over 01", "allocations per step"], rows) +
            f"\nMeasured by `./tutorial.sh bench` on {mesh['file']} ({mesh['nodes']} nodes, "
            f"{mesh['tets']} tets), {data['scene']} scene, {data['machine']['cpu']} "
            f"({machine_summary(data['machine'])}), "
            f"{b['compiler']} `{b['flags']}`, commit {data['commit']}.\n")


def reference_row(data, name):
    """The row a chapter's row is compared with: the row before it, except that a threaded row
    compares with the chapter before at the same thread count (10@2 with 09@2); without one
    (09@2: chapter 08 runs on one thread) with the row before (09@1)."""
    rows = data["chapters"]
    i = next(k for k, x in enumerate(rows) if x["chapter"] == name)
    same_threads = [x for x in rows[:i] if chapter_dir(x["chapter"]) != chapter_dir(name)
                    and x.get("threads", 1) == rows[i].get("threads", 1)]
    if "@" in name and same_threads:
        return same_threads[-1]
    return rows[i - 1] if i > 0 else None


# A phase whose time moves by less than this share of the reference row's step is noise for
# the chapter map: 0.02 ms of constraints at x1.02 is not what a chapter is about.
MOVED_SHARE = 0.02


def moved_most(c, ref):
    """The phase a chapter moves most against its reference row, by the milliseconds it saves
    or costs, not by the ratio (a ratio of two tiny times is noise); in either direction,
    with its ratio; "no phase by more than 2% of the step" when none moves that much."""
    phases = ALL_PHASES[:-1]
    phase = max(phases, key=lambda p: abs(ref["median_ms"][p] - c["median_ms"][p]))
    change = abs(ref["median_ms"][phase] - c["median_ms"][phase])
    if change < MOVED_SHARE * ref["median_ms"]["step"]:
        return f"no phase by more than {100 * MOVED_SHARE:g}% of the step over `{ref['chapter']}`"
    return (f"{PHASE_LABELS[phase]} {ratio(ref['median_ms'][phase], c['median_ms'][phase])} "
            f"over `{ref['chapter']}`")


def readme_title(root, name, fallback):
    """The title in `# Chapter NN: <title>`, the first line of the chapter's README."""
    readme = root / "chapters" / chapter_dir(name) / "README.md"
    if readme.exists():
        match = re.match(r"# Chapter \w+: (.+)", readme.read_text().split("\n", 1)[0])
        if match:
            return match.group(1).strip()
    return fallback


def chapter_map(data):
    """One line per chapter: the idea, the phase it moves most, the overall step speedup."""
    by = chapters_by_name(data)
    base = by.get(BASELINE)
    rows, previous = [], None
    for c in data["chapters"]:
        name = c["chapter"]
        moved = "the baseline"
        ref = reference_row(data, name)
        if ref is not None and c["median_ms"]["dfdx"] == 0 < ref["median_ms"]["dfdx"]:
            # A fused element pass (chapter 08) has no df/dx phase of its own: compare the three
            # phases it replaces together, not a zero.
            fused = ("forces", "dfdx", "compose")
            moved = (f"forces + df/dx + composition (fused) "
                     f"{ratio(sum(ref['median_ms'][p] for p in fused), sum(c['median_ms'][p] for p in fused))} "
                     f"over `{ref['chapter']}`")
        elif ref is not None:
            moved = moved_most(c, ref)
        diff = f"[diff](docs/diffs/{chapter_dir(name)}.diff)" if previous is not None and \
            chapter_dir(previous["chapter"]) != chapter_dir(name) else ""
        rows.append([f"[`{name}`](chapters/{chapter_dir(name)}/README.md)", c.get("title", ""), moved,
                     ratio(base["median_ms"]["step"], c["median_ms"]["step"]) if base else "-", diff])
        previous = c
    return table(["chapter", "the idea", "the phase it moves most (by time)", "step speedup over 01", "diff"],
                 rows, ["---", "---", "---", "---:", "---"])


def chapter_table(data, name):
    by = chapters_by_name(data)
    c = by[name]
    previous = reference_row(data, name)
    shown = [x for x in (by.get(BASELINE), previous, c) if x is not None]
    shown = [x for i, x in enumerate(shown) if x not in shown[:i]]
    rows = [[f"`{x['chapter']}`"] + [ms(x["median_ms"][p]) for p in ALL_PHASES] +
            [f"{x['allocations_per_step']:g}", f"{x['cg_iterations']:g}"] for x in shown]
    refs = [r for r in (by.get(BASELINE), previous) if r is not None and r is not c]
    for ref in [r for i, r in enumerate(refs) if r not in refs[:i]]:  # 02: previous is 01
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
            f"[docs/results.md](../../docs/results.md).{fused_note} Generated by `tools/femtools/docs/update.py`.\n")


def regimes_points_table(reg):
    """One row per point of the regime sweep: chapter 01's CG iterations and solve share, the
    overall step's speedup of every chapter over 01, and the solve table's two poster ratios."""
    names = [n for n in regimes_common.chapter_names(reg) if n != BASELINE]
    rows = []
    for body in reg["bodies"]:
        for p in regimes_common.body_points(reg, body):
            ratios = [regimes_common.solver_ratio(p, k) for k in ("eigen_cg_guess", "pcg_ch06")]
            rows.append([f"`{body}`", f"{p['E']:g}", f"{regimes_common.iterations(p):g}",
                         f"{100 * regimes_common.share(p, 'solve'):.0f}%", ms(p["chapters"][0]["median_ms"]["step"])] +
                        [f"x{regimes_common.speedup(p, n):.2f}" for n in names] +
                        [f"x{r:.2f}" if r else "-" for r in ratios])
    return table(["body", "E (Pa)", "01's CG it.", "solve share of 01's step", "01's step (ms)"] +
                 [f"`{n[:2]}`" for n in names] + ["`solveWithGuess()`", "our PCG"], rows,
                 ["---"] + ["---:"] * (len(names) + 6))


def regimes_solvers_table(reg):
    """The whole solve table at the softest and the stiffest point of each body."""
    shown = []
    for body in reg["bodies"]:
        pts = regimes_common.body_points(reg, body)
        shown += [pts[0], pts[-1]] if len(pts) > 1 else pts
    if not all(p.get("solvers") for p in shown):
        return "(the sweep ran with --no-solvers)\n"
    names = [s["name"] for s in shown[0]["solvers"]]
    rows = []
    for n in names:
        cells = []
        for p in shown:
            s = next(x for x in p["solvers"] if x["name"] == n)
            cells.append(f"{ms(s['median_ms'])} ({ratio(p['solvers'][0]['median_ms'], s['median_ms'])}, "
                         f"{s['iterations']:g} it., {s['allocations_per_solve']:g} alloc.)")
        poster = POSTER_SOLVE_MS.get(n)
        rows.append([f"`{n}`"] + cells + [f"{poster:g} ms" if poster else "-"])
    header = [f"`{p['body']}`, E = {p['E']:g} (01: {regimes_common.iterations(p):g} it.)" for p in shown]
    ends = "; ".join(
        f"`{body}`: x{regimes_common.solver_ratio(pts[0], 'pcg_ch06'):.2f} at the softest point, "
        f"x{regimes_common.solver_ratio(pts[-1], 'pcg_ch06'):.2f} at the stiffest"
        for body, pts in ((b, regimes_common.body_points(reg, b)) for b in reg["bodies"]))
    return (table(["solver: median ms (vs `eigen_cg`, iterations, allocations)"] + header + ["poster"], rows) +
            f"\nOur PCG over Eigen's `solve()` (poster x4.226): {ends}.\n")


def update_regimes(root, path, images, stale=None):
    """The regime sweep's generated sections (results/regimes.json, kept as docs/data/regimes.json,
    the JSON behind the committed docs): without a sweep, the committed sections stay."""
    data_copy = root / "docs" / "data" / "regimes.json"
    source = path or root / "results" / "regimes.json"
    if not source.exists():
        if path is not None or not data_copy.exists():
            print(f"no {source}: the regime sections stay as they are (./tutorial.sh regimes)")
            return
        source = data_copy
    try:
        reg = load(source)
    except ResultsError as e:
        die(f"fem-tools docs update: {e}")
    problems = regimes_common.validate_regimes(reg)
    if problems:
        die(f"fem-tools docs update: {source} does not match the regimes schema:\n  " + "\n  ".join(problems))
    if source.resolve() != data_copy.resolve() and stale is None:
        data_copy.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(source, data_copy)
        print(f"copied {source.name} to {data_copy.parent}")
    poster = regimes_common.poster_statements(reg)
    update_file(root / "docs" / "results.md", {"regimes:poster": poster,
                                               "regimes:points": regimes_points_table(reg),
                                               "regimes:solvers": regimes_solvers_table(reg)},
                stale)
    update_file(root / "README.md", {"regimes:poster": poster}, stale)
    if stale is not None:
        return
    png = source.with_name("regimes.png")
    if images and png.exists() and source != data_copy:
        images = images if images.is_absolute() else root / images
        images.mkdir(parents=True, exist_ok=True)
        shutil.copy(png, images / png.name)
        print(f"copied {png.name} to {images}")


def threads_table(threads, bench=None):
    """Chapter 09 per thread count (docs/data/threads.json, from ./tutorial.sh threads): every
    phase, and the speedup of each over the same chapter on one thread. A run of its own: when
    it is not the benchmark's run (bench), the note under it says so, so that no reader compares
    its milliseconds with the bench tables beside it."""
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
            f"(`./tutorial.sh threads`) on {m['cpu']} ({machine_summary(m)})"
            + (f", 1-minute load average {m['load_average'][0]:.1f} at the start, "
               f"{m['load_average'][1]:.1f} at the end" if "load_average" in m else "") + ", "
            f"{b['compiler']} `{b['flags']}`, commit {threads['commit']}."
            + (f" A run of its own, not the benchmark run of commit {bench['commit']} of the tables above: "
               "compare the rows of one table, not milliseconds across tables."
               if bench is not None and bench.get("commit") != threads.get("commit") else "")
            + " Generated by `tools/femtools/docs/update.py`.\n")


def replace(text, name, body):
    """Replaces what stands between <!-- name:begin --> and <!-- name:end -->."""
    begin, end = f"<!-- {name}:begin -->", f"<!-- {name}:end -->"
    pattern = re.compile(re.escape(begin) + ".*?" + re.escape(end), re.S)
    if not pattern.search(text):
        return text, False
    return pattern.sub(lambda _: begin + "\n" + body + end, text), True


def update_file(path, sections, stale=None):
    """Writes the sections into path; with a list `stale`, writes nothing and appends to it
    the sections whose committed text differs."""
    if not path.exists():
        print(f"note: {path} is missing, skipped")
        return
    original = text = path.read_text()
    done = []
    for name, body in sections.items():
        before = text
        text, found = replace(text, name, body)
        if found:
            done.append(name)
            if stale is not None and text != before:
                stale.append(f"{path}: {name}")
    if stale is not None:
        return
    if text != original:
        path.write_text(text)
    if done:
        print(f"updated {path}: {', '.join(done)}")


def main(argv=None, prog=None):
    root_default = ROOT
    parser = argparse.ArgumentParser(prog=prog, description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--root", type=pathlib.Path, default=root_default, help="repository root")
    parser.add_argument("--bench", type=pathlib.Path, help="default: ROOT/docs/data/bench.json")
    parser.add_argument("--scaling", type=pathlib.Path, help="default: ROOT/docs/data/scaling.json if present")
    parser.add_argument("--viewer", type=pathlib.Path, help="default: ROOT/docs/data/viewer.json if present")
    parser.add_argument("--threads", type=pathlib.Path, help="default: ROOT/docs/data/threads.json if present")
    parser.add_argument("--regimes", type=pathlib.Path,
                        help="default: ROOT/results/regimes.json, else ROOT/docs/data/regimes.json")
    parser.add_argument("--check", action="store_true",
                        help="write nothing; exit 1 if a generated section differs from the JSON")
    parser.add_argument("--images", type=pathlib.Path, nargs="?", const=pathlib.Path("docs/images"),
                        help="copy the PNG plots from the results directory here (default docs/images)")
    parser.add_argument("--only-regimes", action="store_true",
                        help="only the regime sweep's sections (no results/bench.json needed)")
    args = parser.parse_args(argv)
    root = args.root
    if args.only_regimes:
        update_regimes(root, args.regimes, args.images)
        return
    data_dir = root / "docs" / "data"
    bench_path = args.bench or data_dir / "bench.json"
    scaling_path = args.scaling or data_dir / "scaling.json"
    try:
        data = load_checked(bench_path)
        scaling = load_checked(scaling_path, scaling=True) if scaling_path.exists() else None
        viewer_path = args.viewer or data_dir / "viewer.json"
        viewer = load_checked(viewer_path, viewer=True) if viewer_path.exists() else None
        threads_path = args.threads or data_dir / "threads.json"
        threads = load_checked(threads_path) if threads_path.exists() else None
    except ResultsError as e:
        die(f"fem-tools docs update: {e}")

    # A chapter's title is its README's heading (chapters/registry.cmake): read it from there, so
    # that a heading rewritten since the benchmark ran shows in the chapter map at once.
    for c in data["chapters"]:
        c["title"] = readme_title(root, c["chapter"], c.get("title", ""))
    solvers = solvers_table(data)
    tables = {
        "results:machine": machine_table(data), "results:phases": phases_table(data),
        "results:speedups": speedups_table(data), "results:allocations": allocations_table(data),
        "results:solvers": solvers}
    # The scaling run takes tens of minutes and is optional: without results/scaling.json the
    # committed table stays as it is (a placeholder goes in only where there is no table yet).
    if scaling is not None or "run `./tutorial.sh scaling`" in (root / "docs" / "results.md").read_text():
        tables["results:scaling"] = scaling_table(scaling)
    elif not args.check:
        print(f"no {scaling_path}: the scaling table in docs/results.md is left as it is")
    stale = [] if args.check else None
    update_file(root / "docs" / "results.md", tables, stale)
    update_file(root / "README.md", {"headline": headline(data), "chapter-map": chapter_map(data)}, stale)
    if viewer is not None:  # like the scaling table: optional, kept as it is without a new run
        update_file(root / "docs" / "results.md", {"viewer-fps": viewer_table(viewer)}, stale)
    for c in data["chapters"]:
        update_file(root / "chapters" / chapter_dir(c["chapter"]) / "README.md",
                    {f"bench-table:{c['chapter']}": chapter_table(data, c["chapter"]),
                     "results:solvers": solvers}, stale)
    if scaling is not None:
        update_file(root / "chapters" / "10_multigrid" / "README.md",
                    {"multigrid-scaling": multigrid_scaling(scaling)}, stale)
        update_file(root / "chapters" / "11_node_order" / "README.md",
                    {"node-order-scaling": pair_scaling(scaling, "10_multigrid", "11_node_order")}, stale)
        update_file(root / "chapters" / "12_half_the_bytes" / "README.md",
                    {"half-the-bytes-scaling": pair_scaling(scaling, "11_node_order", "12_half_the_bytes")},
                    stale)
    if threads is not None:  # like the scaling table: kept as it is without a new run
        update_file(root / "chapters" / "09_threads" / "README.md",
                    {"threads-table": threads_table(threads, data)}, stale)
    if args.check:
        # The regime sections are checked against the committed sweep only.
        update_regimes(root, args.regimes or data_dir / "regimes.json", None, stale)
        for s in stale:
            print(f"stale: {s} differs from what {bench_path} gives", file=sys.stderr)
        if stale:
            print("fem-tools docs update --check: regenerate with `fem-tools docs update`",
                  file=sys.stderr)
            sys.exit(1)
        print(f"fem-tools docs update --check: every generated section matches {bench_path}")
        return
    if args.images:
        images = args.images if args.images.is_absolute() else root / args.images
        images.mkdir(parents=True, exist_ok=True)
        for png in sorted(bench_path.parent.glob("*.png")):
            shutil.copy(png, images / png.name)
            print(f"copied {png.name} to {images}")
    update_regimes(root, args.regimes, args.images)


if __name__ == "__main__":
    main()
