#!/usr/bin/env python3
"""Tests of a run as a folder and of the hand-in of docs/coursework.md, on the test mesh: a
student's fem_bench --out writes only its own folder (an exercise run never replaces another
run), ./tutorial.sh plots makes the plots from that folder's JSON and says which run they
show, and a teacher given only the JSON regenerates the same plots. Prints 'N passed, M
failed' last.

    test_handin.py --bench build/release/fem_bench"""
import argparse
import pathlib
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parents[2]
PLOTS = ["phases.png", "speedup.png", "allocations.png", "solvers.png"]
results = {"passed": 0, "failed": 0}


def check(name, condition, detail=""):
    results["passed" if condition else "failed"] += 1
    print(f"{'ok  ' if condition else 'FAIL'} {name}{'' if condition else ': ' + str(detail)[:3000]}")


def run(*args):
    return subprocess.run([str(a) for a in args], capture_output=True, text=True, cwd=ROOT)


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--bench", required=True)
    args = parser.parse_args()
    bench = [args.bench, "--mesh", ROOT / "meshes" / "test_beam.msh", "--scene", "sliding",
             "--steps", "3", "--warmup", "1", "--chapters", "01,06"]
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        student, exercise = tmp / "handin" / "06_run", tmp / "handin" / "exercise"

        p = run(*bench, "--out", student)
        check("fem_bench --out DIR exits 0", p.returncode == 0, p.stderr)
        check("fem_bench --out DIR writes DIR/bench.json", (student / "bench.json").exists(), p.stdout)
        check("fem_bench names the scene and the mesh it ran",
              "scene sliding, mesh" in p.stdout and "test_beam.msh" in p.stdout, p.stdout[:500])
        first = (student / "bench.json").read_bytes()
        p = run(*bench, "--out", exercise, "--no-solvers")
        check("another run's folder leaves the first run alone",
              p.returncode == 0 and (student / "bench.json").read_bytes() == first
              and (exercise / "bench.json").exists(), p.stderr)
        p = run(*bench, "--out", student, "--no-solvers")
        check("a run into an existing folder says it replaces that run",
              "replacing the run that was there" in p.stdout, p.stdout[-300:])
        p = run(*bench, "--out", student)  # the hand-in: a full run again
        first = (student / "bench.json").read_bytes()
        p = run(*bench, "--out", "", "--json", tmp / "only.json", "--no-solvers")
        check("--json FILE still writes just that file", p.returncode == 0 and (tmp / "only.json").exists()
              and not (ROOT / "bench.json").exists(), p.stderr)

        # The student's plots, made from the run's own JSON.
        p = run(ROOT / "tutorial.sh", "plots", student)
        check("./tutorial.sh plots DIR exits 0", p.returncode == 0, p.stderr)
        check("the plots say which run they show",
              "sliding scene, test_beam.msh" in p.stdout and str(student / "bench.json") in p.stdout,
              p.stdout)
        for png in PLOTS:
            check(f"{png} written into the run's folder", (student / png).exists()
                  and (student / png).stat().st_size > 10_000)

        # The teacher: only the JSON of the hand-in, the plots regenerated, the same files.
        teacher = tmp / "teacher"
        teacher.mkdir()
        (teacher / "bench.json").write_bytes(first)
        p = run(ROOT / ".venv" / "bin" / "python", ROOT / "scripts" / "plot_results.py",
                teacher / "bench.json", "--out", teacher)
        check("the teacher's regeneration exits 0", p.returncode == 0, p.stderr)
        for png in PLOTS:
            same = (teacher / png).exists() and (teacher / png).read_bytes() == (student / png).read_bytes()
            check(f"the teacher regenerates the student's {png} byte for byte", same)
    print(f"{results['passed']} passed, {results['failed']} failed")
    return 1 if results["failed"] else 0


if __name__ == "__main__":
    sys.exit(main())
