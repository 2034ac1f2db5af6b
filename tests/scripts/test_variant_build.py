#!/usr/bin/env python3
"""A variant of every chapter whose folder holds more than one source file (its stepper and
the roofline's work.cpp, and the building blocks or lesson it teaches: today every chapter) is made with
`fem-tools course variant` in a copy of the repository, built with the rest (every .cpp of a
chapter's folder is compiled), passes the checks every chapter passes (the generic tests
under its own name), runs beside its original in one fem_bench run, and its copy of the
lesson measures it beside the original's (fem_lessons LESSON --chapter VARIANT). Prints
'N passed, M failed' last.

    test_variant_build.py --venv .venv   # builds a copy: its variants' files, the rest from ccache"""
import argparse
import json
import pathlib
import shutil
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parents[2]
results = {"passed": 0, "failed": 0}


def check(name, condition, detail=""):
    results["passed" if condition else "failed"] += 1
    print(f"{'ok  ' if condition else 'FAIL'} {name}{'' if condition else ': ' + str(detail)[-3000:]}",
          flush=True)


def run(*args, cwd=None):
    return subprocess.run([str(a) for a in args], capture_output=True, text=True, cwd=cwd)


def copy_repo(tmp, venv):
    def ignore(directory, names):
        return {n for n in names if n in ("__pycache__", "build", ".venv")
                or (pathlib.Path(directory) / n / "variant_of").exists()}
    repo = tmp / "repo"
    for part in ("chapters", "common", "femcourse", "cmake", "apps", "tests", "tools"):
        shutil.copytree(ROOT / part, repo / part, ignore=ignore)
    (repo / "meshes").mkdir()
    for mesh in ("test_beam.msh", "plate_poster.msh"):
        shutil.copy(ROOT / "meshes" / mesh, repo / "meshes" / mesh)
    for name in ("CMakeLists.txt", "CMakePresets.json"):
        shutil.copy(ROOT / name, repo / name)
    # The venv linked, not named by its path: the copy's command lines then name it as the
    # original's do (relative to the build folder, CMakeLists.txt's CCACHE_BASEDIR), and
    # ccache serves every file the variants leave unchanged from the original's build.
    (repo / ".venv").symlink_to(pathlib.Path(venv).resolve())
    return repo


def multi_source_chapters(repo):
    return [d.name for d in sorted((repo / "chapters").iterdir())
            if d.is_dir() and (d / "stepper.hpp").exists() and not (d / "variant_of").exists()
            and len(list(d.glob("*.cpp"))) > 1]


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--venv", default=str(ROOT / ".venv"))
    parser.add_argument("--keep", help="build in this folder and keep it")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(args.keep) if args.keep else pathlib.Path(tmp)
        repo = copy_repo(tmp, args.venv)
        originals = multi_source_chapters(repo)
        check("chapters 07, 09 and 10 have more than one source file",
              {"07_block_sparse", "09_threads", "10_multigrid"} <= set(originals), originals)
        variants = []
        for original in originals:
            p = run(sys.executable, "-m", "femtools", "course", "variant", "--root", repo, original[:2], "mine")
            check(f"fem-tools course variant {original[:2]} mine", p.returncode == 0, p.stderr)
            variants.append(original[:2] + "_mine")

        # The release preset's folder, as in the original: the same depth below the root
        # gives the same relative paths, hence ccache hits for every unchanged file.
        build = repo / "build" / "release"
        print(f"building {len(variants)} variants beside their originals", flush=True)
        p = run("cmake", "--preset", "release", cwd=repo)
        check("the copy configures", p.returncode == 0, p.stdout + p.stderr)
        p = run("cmake", "--build", build, "--target", "fem_bench", "fem_lessons", "test_every_chapter")
        check("the copy builds with every variant (each folder's .cpp files compiled)",
              p.returncode == 0, p.stdout + p.stderr)
        if p.returncode != 0:
            print(f"{results['passed']} passed, {results['failed']} failed")
            return 1

        for variant in variants:
            p = run(build / "tests" / "test_every_chapter", f"{variant}:*", "--warn", "NoAssertions")
            check(f"{variant} passes the checks every chapter passes", p.returncode == 0
                  and "All tests passed" in p.stdout, p.stdout + p.stderr)

        measured = sorted(originals + variants)
        out = tmp / "bench.json"
        p = run(build / "fem_bench", "--mesh", repo / "meshes" / "test_beam.msh", "--steps", "2",
                "--warmup", "1", "--threads", "1", "--no-solvers", "--chapters", ",".join(measured), "--json", out)
        check("fem_bench runs the variants beside their originals", p.returncode == 0, p.stderr)
        rows = json.loads(out.read_text())["chapters"] if out.exists() else []
        names = {r["chapter"].split("@")[0] for r in rows}
        check("the run's JSON holds every original and every variant", set(measured) <= names,
              sorted(names))

        lessons = {"08": "rotations", "09": "threads-element", "10": "multigrid", "07": "spmv"}
        for number, lesson in lessons.items():
            p = run(build / "fem_lessons", lesson, "--chapter", f"{number}_mine", "--mesh",
                    repo / "meshes" / "test_beam.msh", "--steps", "2")
            check(f"fem_lessons {lesson} --chapter {number}_mine measures the variant beside the original",
                  p.returncode == 0 and f"### {number}_mine" in p.stdout
                  and p.stdout.count("\n### ") == 2, p.stdout[-2000:] + p.stderr)

    print(f"{results['passed']} passed, {results['failed']} failed")
    return 1 if results["failed"] else 0


if __name__ == "__main__":
    sys.exit(main())
