"""Runs the chapters over the beam series and the large beams (about 500 to 100,000 nodes)
and writes results/scaling.json. Each run (one chapter on one mesh) has a time budget: a
chapter that exceeds it stops there, and the plot marks where.

    fem-tools runs scaling --bench build/release/fem_bench --out results/scaling.json
"""
import json
import pathlib
import subprocess
import sys
import tempfile
import time

from femtools.args import command_parser
from femtools.paths import ROOT
from femtools.files import write_text
COMMITTED = ["beam_500", "beam_1k", "beam_2k", "beam_5k", "beam_10k"]
LARGE = ["beam_20k", "beam_50k", "beam_100k"]


def mesh_path(name):
    committed = ROOT / "meshes" / f"{name}.msh"
    return committed if committed.exists() else ROOT / "meshes" / "generated" / f"{name}.msh"


def arguments(argv, prog):
    parser = command_parser(prog, __doc__)
    parser.add_argument("--bench", default=str(ROOT / "build" / "release" / "fem_bench"))
    parser.add_argument("--out", default=str(ROOT / "results" / "scaling.json"))
    parser.add_argument("--chapters", default="all", help="comma-separated, or all")
    parser.add_argument("--steps", type=int, default=5, help="measured steps per run")
    parser.add_argument("--warmup", type=int, default=1)
    parser.add_argument("--budget", type=float, default=60.0, help="seconds per run before a chapter stops")
    parser.add_argument("--no-large", action="store_true", help="only the committed beams (up to 10k nodes)")
    args = parser.parse_args(argv)
    if args.steps <= 0 or args.warmup < 1 or args.budget <= 0:
        parser.error("--steps, --warmup and --budget must be positive (the first step allocates the steppers' buffers)")
    return args


def generate_missing(names):
    """The large beams are generated on demand (gmsh), not committed."""
    missing = [n for n in names if not mesh_path(n).exists()]
    if missing:
        print(f"generating {', '.join(missing)} (gmsh)", flush=True)
        subprocess.run([sys.executable, str(ROOT / "meshes" / "generate.py"), "--only", *missing],
                       check=True)


def main(argv=None, prog=None):
    args = arguments(argv, prog)
    names = COMMITTED + ([] if args.no_large else LARGE)
    generate_missing(names)
    listing = subprocess.run([args.bench, "--help"], capture_output=True, text=True, check=True)
    del listing  # fem_bench exists and runs
    chapters = None if args.chapters == "all" else args.chapters.split(",")
    active, runs, skipped, header = None, [], [], None
    with tempfile.TemporaryDirectory() as tmp:
        for name in names:
            todo = active if active is not None else (chapters or ["all"])
            if not todo:
                break
            for chapter in list(todo):
                json_path = pathlib.Path(tmp) / f"{name}_{chapter}.json"
                cmd = [args.bench, "--mesh", str(mesh_path(name)), "--chapters", chapter,
                       "--steps", str(args.steps), "--warmup", str(args.warmup), "--no-solvers",
                       "--json", str(json_path)]
                start = time.time()
                try:
                    subprocess.run(cmd, capture_output=True, text=True, check=True, timeout=args.budget)
                except subprocess.TimeoutExpired:
                    print(f"  {name:10s} {chapter:24s} over the {args.budget:g} s budget: stops here", flush=True)
                    skipped.append({"chapter": chapter, "mesh": name, "reason": f"over {args.budget:g} s"})
                    todo.remove(chapter)
                    continue
                data = json.loads(json_path.read_text())
                header = header or data
                for c in data["chapters"]:
                    runs.append({"chapter": c["chapter"], "mesh": name, "nodes": data["mesh"]["nodes"],
                                 "tets": data["mesh"]["tets"], "step_ms": c["median_ms"]["step"],
                                 "solve_ms": c["median_ms"]["solve"], "cg_iterations": c["cg_iterations"],
                                 "allocations_per_step": c["allocations_per_step"]})
                    print(f"  {name:10s} {c['chapter']:24s} {data['mesh']['nodes']:7d} nodes  step "
                          f"{c['median_ms']['step']:10.2f} ms  ({time.time() - start:5.1f} s)", flush=True)
                if chapter == "all":  # the first size names the chapters (09_threads@1 and @2: one run)
                    active = list(dict.fromkeys(c["chapter"].split("@")[0] for c in data["chapters"]))
            if active is None:
                active = list(todo)
    if header is None:
        sys.exit("fem-tools runs scaling: no run finished within the budget")
    result = {"schema_version": 1, "scene": header["scene"], "steps": args.steps,
              "warmup_steps": args.warmup, "dt": header["dt"], "cg_tolerance": header["cg_tolerance"],
              "build": header["build"], "machine": header["machine"], "commit": header["commit"],
              "uncommitted": header.get("uncommitted"), "budget_seconds": args.budget, "runs": runs, "skipped": skipped}
    out = pathlib.Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    write_text(out, json.dumps(result, indent=1) + "\n")
    print(f"wrote {out}")
