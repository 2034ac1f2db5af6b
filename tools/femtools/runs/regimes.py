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

from femtools.args import command_parser
from femtools.files import write_text
from femtools.paths import ROOT
from femtools.results.common import BASELINE, ResultsError, die, load
from femtools.results.regimes import HEADER_KEYS, chapter_names, iterations, share, speedup, validate_regimes

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


def main(argv=None, prog=None):
    parser = command_parser(prog, __doc__)
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
        write_text(args.out, json.dumps(data, indent=1) + "\n")
        print(f"wrote {args.out}")
        out_png = args.plot or args.out.with_name("regimes.png")
    problems = validate_regimes(data)
    if problems:
        die("fem-tools runs regimes: the sweep does not match its schema:\n  " + "\n  ".join(problems))
    from femtools.plots.regimes import plot  # matplotlib only here: --help and a sweep run without it
    plot(data, out_png)
