"""The regime sweep: every chapter on both poster-sized bodies over a sweep of Young's modulus,
to show where each optimization pays. Runs build/release/fem_bench once per (body, E) point
(all chapters interleaved step by step, the solve table on the same systems) and writes
results/regimes.json (schema in README.md) and the plot results/regimes.png.

The knob is E at the default dt: the system is A = (1 + h alpha) M + (h beta + h^2) K(E), so E
scales the stiffness term and nothing else, whereas dt would also change the motion per
step, the warm start's quality and the frame time an interactive application is built for.

    fem-tools runs regimes                           # the full sweep (minutes)
    fem-tools runs regimes --E 1e4,1e6 --bodies meshes/test_beam.msh --steps 2
    fem-tools runs regimes --plot-only results/regimes.json
"""
import argparse
import json
import pathlib
import subprocess
import tempfile
import time

from femtools.results.regimes import (HEADER_KEYS, POSTER_NUMBERS, SHARE_PHASES, body_points,
                            chapter_names, iterations, share, solver_ratio, speedup,
                            validate_regimes)
from femtools.results.common import BASELINE, PHASE_LABELS, ResultsError, die, footer, load

from femtools.paths import ROOT
BODIES = ["meshes/plate_poster.msh", "meshes/perforated_bar_poster.msh"]
# Half-decade steps (1, 3, 10, ...) over four and a half decades: from a soft body that chapter 01's
# CG solves in a handful of iterations to a stiff one that takes it hundreds (beyond, the stiff
# plate's points cost most of the sweep's time and add no new regime).
E_VALUES = [1e3, 3e3, 1e4, 3e4, 1e5, 3e5, 1e6, 3e6, 1e7, 3e7]


def numbers(text):
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected comma-separated numbers, got {text!r}")
    if not values or any(not v > 0 for v in values):
        raise argparse.ArgumentTypeError("every E must be positive")
    return sorted(set(values))


def run_point(args, mesh, e, json_path):
    """One fem_bench run; its progress lines go through, indented."""
    cmd = [args.bench, "--mesh", str(mesh), "--E", repr(e), "--scene", args.scene,
           "--chapters", args.chapters, "--steps", str(args.steps), "--warmup", str(args.warmup),
           "--json", str(json_path), "--replace"] + (["--no-solvers"] if args.no_solvers else [])
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    for line in proc.stdout:
        if line.startswith("  step") or "warning" in line or "solve table" in line:
            print("    " + line.strip(), flush=True)
    err = proc.stderr.read()
    if proc.wait() != 0:
        die(f"fem-tools runs regimes: fem_bench failed on {mesh} at E = {e:g} (exit {proc.returncode}):\n"
            f"  {' '.join(cmd)}\n{err}")
    return json.loads(json_path.read_text())


def sweep(args):
    bodies = [pathlib.Path(b) if pathlib.Path(b).is_absolute() else ROOT / b for b in args.bodies]
    missing = [str(b) for b in bodies if not b.exists()]
    if missing:
        die(f"fem-tools runs regimes: no such mesh {', '.join(missing)} (./tutorial.sh meshes)")
    if not pathlib.Path(args.bench).exists():
        die(f"fem-tools runs regimes: no {args.bench} (./tutorial.sh build)")
    total = len(bodies) * len(args.E)
    print(f"regime sweep: {len(bodies)} bodies x {len(args.E)} values of E = {total} points, "
          f"{args.warmup} warm-up + {args.steps} measured steps each, chapters: {args.chapters}",
          flush=True)
    result, points, start = None, [], time.time()
    with tempfile.TemporaryDirectory() as tmp:
        for body in bodies:
            for e in args.E:
                k = len(points) + 1
                print(f"[{k}/{total}] {body.name}, E = {e:g} Pa", flush=True)
                data = run_point(args, body, e, pathlib.Path(tmp) / f"point{k}.json")
                if result is None:
                    result = {key: data[key] for key in HEADER_KEYS}
                    result["uncommitted"] = data.get("uncommitted")  # what differs from the commit
                    result.update({"knob": "E", "bodies": [b.stem for b in bodies], "E_values": args.E,
                                   "chapters_option": args.chapters})
                point = {"body": body.stem, "E": e, "mesh": data["mesh"], "material": data["material"],
                         "chapters": data["chapters"]}
                if "solvers" in data:
                    point["solvers"] = data["solvers"]
                points.append(point)
                elapsed = time.time() - start
                gains = ", ".join(f"{c[:2]} x{speedup(point, c):.2f}" for c in chapter_names({"points": [point]})
                                  if c != BASELINE)
                print(f"    01's CG {iterations(point):g} iterations, solve {100 * share(point, 'solve'):.0f}% of "
                      f"01's step; step speedup over 01: {gains}  ({elapsed:.0f} s, about "
                      f"{elapsed / k * (total - k):.0f} s to go)", flush=True)
    result["points"] = points
    return result


def chapter_colours(names):
    import matplotlib.pyplot as plt
    cmap = plt.get_cmap("tab10" if len(names) <= 10 else "tab20")
    return {n: cmap(i % cmap.N) for i, n in enumerate(names)}


BODY_STYLES = [("-", "o"), ("--", "s"), (":", "^"), ("-.", "D")]
# The solve table's two ratios the poster reports: colour, what the solver is.
SOLVER_LINES = {"eigen_cg_guess": ("tab:orange", "Eigen solveWithGuess()"), "pcg_ch06": ("tab:purple", "ours")}


def poster_number(key):
    return next(target for k, _, target in POSTER_NUMBERS if k == key)


def plot(data, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D
    from matplotlib.ticker import FuncFormatter

    names = chapter_names(data)
    colours = chapter_colours(names)
    styles = {b: BODY_STYLES[i % len(BODY_STYLES)] for i, b in enumerate(data["bodies"])}
    have_solvers = all(p.get("solvers") for p in data["points"])
    fig, axes = plt.subplots(1, 3 if have_solvers else 2, figsize=(18 if have_solvers else 13, 5.8))
    ax_step, ax_share = axes[0], axes[-1]

    for body in data["bodies"]:
        pts = body_points(data, body)
        xs = [iterations(p) for p in pts]
        line, marker = styles[body]
        for n in names:
            if n != BASELINE:
                ax_step.plot(xs, [speedup(p, n) for p in pts], line, marker=marker, ms=4, color=colours[n])
        for i, phase in enumerate(SHARE_PHASES + ["other"]):
            ax_share.plot(xs, [100 * share(p, phase) for p in pts], line, marker=marker, ms=4,
                          color=plt.get_cmap("Dark2")(i))
        if have_solvers:
            for key, (colour, _) in SOLVER_LINES.items():
                axes[1].plot(xs, [solver_ratio(p, key) for p in pts], line, marker=marker, ms=4, color=colour)
    step_target = poster_number("step")
    ax_step.axhline(step_target, color="black", lw=1.2, ls=(0, (6, 3)))
    ax_step.annotate(f"poster x{step_target:g}", (0.01, step_target), xycoords=("axes fraction", "data"),
                     va="bottom", fontsize=8)
    ax_step.axhline(1.0, color="0.5", lw=0.7)
    ax_step.set_yscale("log")
    ax_step.set_ylabel(f"overall step speedup over {BASELINE} (median ratio, log)")
    ax_step.set_title("Overall step: speedup over chapter 01")
    chapter_handles = [Line2D([], [], color=colours[n], label=n) for n in names if n != BASELINE]
    body_handles = [Line2D([], [], color="0.3", ls=styles[b][0], marker=styles[b][1], label=b)
                    for b in data["bodies"]]
    ax_step.legend(handles=chapter_handles + body_handles, fontsize=7, ncol=2)

    if have_solvers:
        ax = axes[1]
        for key, (colour, _) in SOLVER_LINES.items():
            target = poster_number(key)
            ax.axhline(target, color=colour, lw=1.0, ls=(0, (6, 3)))
            ax.annotate(f"poster x{target:g}", (0.01, target), xycoords=("axes fraction", "data"),
                        va="bottom", fontsize=8, color=colour)
        ax.axhline(1.0, color="0.5", lw=0.7)
        ax.set_yscale("log")
        ax.set_ylabel("Eigen solve() time over the solver's (median ratio, log)")
        ax.set_title("The solve table: the same systems, the same tolerance")
        ax.legend(handles=[Line2D([], [], color=c, label=f"{key} ({what})")
                           for key, (c, what) in SOLVER_LINES.items()] + body_handles, fontsize=7)

    ax_share.set_ylabel("share of chapter 01's median step [%]")
    ax_share.set_ylim(0, 100)
    ax_share.set_title("Where chapter 01's step goes (Amdahl: what is left to gain)")
    ax_share.legend(handles=[Line2D([], [], color=plt.get_cmap("Dark2")(i),
                                    label=PHASE_LABELS.get(ph, "other (update, copies)"))
                             for i, ph in enumerate(SHARE_PHASES + ["other"])] + body_handles, fontsize=7)
    for ax in axes[:-1]:  # ratios on a log scale, labelled as plain ratios
        ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"x{v:g}"))
        ax.yaxis.set_minor_formatter(FuncFormatter(lambda v, _: f"x{v:g}" if str(v)[0] in "235" else ""))
    for ax in axes:
        ax.set_xscale("log")
        ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
        ax.xaxis.set_minor_formatter(FuncFormatter(lambda v, _: f"{v:g}" if str(v)[0] in "25" else ""))
        ax.set_xlabel("chapter 01's CG iterations per step (median, log)")
        ax.grid(which="both", alpha=0.3)
    e = data["E_values"]
    fig.suptitle(f"Regimes: Young's modulus E from {min(e):g} to {max(e):g} Pa at dt = {data['dt']:g} s; "
                 "the stiffer, the more CG iterations", fontsize=10)
    head = dict(data, mesh=None, steps=data["steps"])
    fig.text(0.01, 0.005, f"{', '.join(data['bodies'])}, {data['steps']} steps per point | " + footer(head),
             fontsize=6.5, color="0.35", ha="left", va="bottom", wrap=True)
    fig.tight_layout(rect=(0, 0.04, 1, 0.97))
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    print(f"wrote {path}")


def main(argv=None, prog=None):
    parser = argparse.ArgumentParser(prog=prog, description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--bench", default=str(ROOT / "build" / "release" / "fem_bench"), help="fem_bench binary")
    parser.add_argument("--bodies", nargs="+", default=BODIES, metavar="MSH",
                        help="meshes (default: the two poster-sized bodies)")
    parser.add_argument("--E", type=numbers, default=E_VALUES,
                        help=f"Young's moduli in Pa, comma-separated (default {','.join(f'{e:g}' for e in E_VALUES)})")
    parser.add_argument("--scene", default="cantilever")
    parser.add_argument("--chapters", default="all", help="passed to fem_bench (default all: the registry)")
    parser.add_argument("--steps", type=int, default=16, help="measured steps per point (default 16)")
    parser.add_argument("--warmup", type=int, default=2, help="unmeasured steps first (default 2)")
    parser.add_argument("--no-solvers", action="store_true", help="skip the solve table")
    parser.add_argument("--out", type=pathlib.Path, default=ROOT / "results" / "regimes.json")
    parser.add_argument("--plot", type=pathlib.Path, help="the PNG (default: regimes.png beside --out)")
    parser.add_argument("--plot-only", type=pathlib.Path, metavar="JSON", help="only plot an existing sweep")
    args = parser.parse_args(argv)
    if args.steps <= 0 or args.warmup < 1:
        parser.error("--steps and --warmup must be positive (the first step allocates the steppers' buffers)")

    if args.plot_only:
        try:
            data = load(args.plot_only)
        except ResultsError as e:
            die(f"fem-tools runs regimes: {e}")
        out_png = args.plot or args.plot_only.with_suffix(".png")
    else:
        data = sweep(args)
        args.out.parent.mkdir(parents=True, exist_ok=True)
        args.out.write_text(json.dumps(data, indent=1) + "\n")
        print(f"wrote {args.out}")
        out_png = args.plot or args.out.with_name("regimes.png")
    problems = validate_regimes(data)
    if problems:
        die("fem-tools runs regimes: the sweep does not match its schema:\n  " + "\n  ".join(problems))
    plot(data, out_png)


if __name__ == "__main__":
    main()
