#!/usr/bin/env python3
"""Tests of a run as a folder and of the hand-in of docs/coursework.md, on the test mesh: a
student's fem_bench --out writes only its own folder (an exercise run never replaces another
run), ./tutorial.sh plots makes the plots from that folder's JSON and says which run they
show, and a teacher given only the JSON regenerates the same plots. Prints 'N passed, M
failed' last.

    test_handin.py --bench build/release/fem_bench"""
import argparse
import json
import pathlib
import subprocess
import sys
import tempfile

from femtools.course import handin as check_handin

ROOT = pathlib.Path(__file__).resolve().parents[2]
PLOTS = ["phases.png", "speedup.png", "allocations.png", "solvers.png"]
results = {"passed": 0, "failed": 0}


def check(name, condition, detail=""):
    results["passed" if condition else "failed"] += 1
    print(f"{'ok  ' if condition else 'FAIL'} {name}{'' if condition else ': ' + str(detail)[:3000]}")


def run(*args, cwd=ROOT):
    return subprocess.run([str(a) for a in args], capture_output=True, text=True, cwd=cwd)


def links_cases(tmp, run_json):
    """The hand-in check reads and writes only regular files inside the hand-in."""
    handin = [sys.executable, "-m", "femtools", "course", "handin", "--no-tests"]
    outside = tmp / "outside"
    outside.mkdir()
    # A dangling link where the check would write the diff: nothing is created outside.
    dangling = tmp / "handin_dangling"
    dangling.mkdir()
    (dangling / "bench.json").write_bytes(run_json)
    (dangling / "06_custom_pcg.diff").symlink_to(outside / "written_through_the_link.diff")
    p = run(*handin, dangling)
    check("handin-check refuses a hand-in holding a dangling link, naming it",
          p.returncode != 0 and "symbolic links" in p.stderr and "06_custom_pcg.diff" in p.stderr,
          p.stdout + p.stderr)
    check("... and writes nothing through it", not any(outside.iterdir()), list(outside.iterdir()))
    # A link to a file outside: not read.
    (outside / "bench.json").write_bytes(run_json)
    linked = tmp / "handin_linked"
    linked.mkdir()
    (linked / "bench.json").symlink_to(outside / "bench.json")
    p = run(*handin, linked)
    check("handin-check refuses bench.json as a link to a file outside the hand-in",
          p.returncode != 0 and "symbolic links" in p.stderr and "bench.json" in p.stderr, p.stderr)
    # Names that climb out of chapters/: in the run's record, on the command line.
    climbing = tmp / "handin_climbing"
    climbing.mkdir()
    record = json.loads(run_json)
    record["chapters"][0]["chapter"] = "../../outside"
    (climbing / "bench.json").write_text(json.dumps(record))
    p = run(*handin, climbing)
    check("handin-check refuses a chapter name with '..' in the run's record",
          p.returncode != 0 and "'../../outside' is not a plain name" in p.stderr, p.stderr)
    (climbing / "bench.json").write_bytes(run_json)
    p = run(*handin, climbing, "--variant", "../06_custom_pcg")
    check("handin-check refuses a --variant with '..'",
          p.returncode != 0 and "not a plain name" in p.stderr, p.stderr)


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
        check("a run into a folder that holds a run is refused before the work, the run kept",
              p.returncode == 2 and "--replace" in p.stderr and "interleaved" not in p.stdout
              and (student / "bench.json").read_bytes() == first, p.stdout[-300:] + p.stderr)
        p = run(*bench, "--out", student, "--no-solvers", "--replace")
        check("--replace replaces it and says so",
              p.returncode == 0 and "replaced the run that was there" in p.stdout, p.stdout[-300:])
        p = run(*bench, "--out", student, "--replace")  # the hand-in: a full run again
        first = (student / "bench.json").read_bytes()

        # Without --out: a new folder per run under results/, and results/latest the newest.
        default = tmp / "default"
        default.mkdir()
        for _ in range(2):
            p = run(*bench, "--no-solvers", cwd=default)
        folders = sorted(d.name for d in (default / "results").glob("run-*"))
        latest = default / "results" / "latest"
        check("two runs without --out make two folders, results/latest the second",
              p.returncode == 0 and len(folders) == 2 and latest.is_symlink()
              and latest.resolve() == (default / "results" / folders[-1]).resolve()
              and all((default / "results" / f / "bench.json").exists() for f in folders),
              f"{folders} {p.stderr}")

        # The JSON ties each chapter's row to its sources: the hash the build recorded equals the
        # one the hand-in check computes from the folder (fem-tools course handin).
        rows = json.loads((student / "bench.json").read_text())["chapters"]
        check("each row records the hash of its chapter's sources, as the hand-in check computes it",
              all(r.get("source_hash") == check_handin.source_hash(ROOT / "chapters" / r["chapter"])
                  for r in rows), [r.get("source_hash") for r in rows])
        p = run(*bench, "--json", tmp / "only.json", "--no-solvers")
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
        p = run(sys.executable, "-m", "femtools", "plots", "bench",
                teacher / "bench.json", "--out", teacher)
        check("the teacher's regeneration exits 0", p.returncode == 0, p.stderr)
        for png in PLOTS:
            same = (teacher / png).exists() and (teacher / png).read_bytes() == (student / png).read_bytes()
            check(f"the teacher regenerates the student's {png} byte for byte", same)
        links_cases(tmp, first)
    print(f"{results['passed']} passed, {results['failed']} failed")
    return 1 if results["failed"] else 0


if __name__ == "__main__":
    sys.exit(main())
