#!/usr/bin/env python3
"""The exercises of chapters 01-12 as a student does them, and a variant of every chapter: in a
copy of the repository (the current files, committed or not), make each code-changing
exercise's variant with `./tutorial.sh variant`, apply a small scripted version of the
exercise's change, build, and run the commands the chapter README gives, checking that

  - each command is written in the README as run here (NAME replaced by the variant's name),
  - it succeeds, or fails where the exercise says a test fails (a fem_bench or fem_lessons
    command on the test mesh where the README leaves the mesh to the poster-sized default:
    on_test_mesh),
  - and it measured the variant, not the original: the variant's row is in fem_bench's table
    and differs from the original's as the change must make it differ.

The same copy holds a variant of every chapter of the range (every chapter has more than one
source file: its stepper and the roofline's work.cpp), built with the rest: one exercise's
variant stands for its chapter where the exercise keeps the checks every chapter passes
(STANDS_FOR), an unchanged copy NN_mine where none does. Each passes those checks under its own
name (the generic tests), runs beside its original in one fem_bench run, and its copy of the
chapter's lesson measures it beside the original's (fem_lessons LESSON --chapter VARIANT): the
variant machinery holds for every chapter, and no chapter's variant is compiled twice.

Not covered: 03/3 (a debug build), the exercises that change no code, and those whose change
is a design of the student's own (a new smoother, float storage, a SIMD kernel). Prints the CPU
seconds of each phase, and 'N passed, M failed' last; a few minutes on 2 cores (the variants'
files compile, ccache serves the rest).

    test_exercises.py [--keep DIR] [--chapters 01-06] [--only 07/3,10/4]"""
import argparse
import json
import os
import pathlib
import re
import resource
import shutil
import subprocess
import sys
import tempfile

from exercises import EXERCISES, LESSONS, STANDS_FOR

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tools"))
from femtools.course.variant import rewrite  # noqa: E402 (the path above first)
results = {"passed": 0, "failed": 0}


def check(name, condition, detail=""):
    results["passed" if condition else "failed"] += 1
    print(f"{'ok  ' if condition else 'FAIL'} {name}{'' if condition else ': ' + str(detail)[-3000:]}",
          flush=True)
    return condition


def phase(name):
    """The CPU seconds (user + system) of the processes run so far: where the time goes."""
    used = resource.getrusage(resource.RUSAGE_CHILDREN)
    print(f"-- {used.ru_utime + used.ru_stime:7.1f} CPU-s after {name}", flush=True)


def on_test_mesh(command):
    """A README's fem_bench or fem_lessons command as the test runs it: on the test mesh when
    the README leaves the mesh to the default (the poster-sized plate, for the student's
    timings). The test asserts counts (allocations, CG iterations, rows), not times, and the
    counts tell the variant from the original on the small mesh too: the poster's seconds
    per command are the student's wait, not the check's (a later --mesh wins)."""
    if "--mesh" in command or not command.startswith(("build/release/fem_bench", "build/release/fem_lessons")):
        return command
    return command + " --mesh meshes/test_beam.msh"


def run(cwd, command, env=None):
    return subprocess.run(command, cwd=cwd, shell=True, capture_output=True, text=True, env=env)


def copy_repository(target):
    """The repository's current files (tracked and untracked, not ignored) and a link to its
    .venv: what a student's clone with the student's own changes holds."""
    listed = subprocess.run(["git", "-C", str(ROOT), "ls-files", "-z", "--cached", "--others",
                             "--exclude-standard"], capture_output=True, check=True).stdout
    for rel in filter(None, listed.decode().split("\0")):
        source = ROOT / rel
        if not source.is_file() or rel.startswith("chapters/") and "/" in rel[9:] and \
                (ROOT / "chapters" / rel.split("/")[1] / "variant_of").exists():
            continue  # the student's own variants stay out of the copy
        (target / rel).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(source, target / rel)
    (target / ".venv").symlink_to((ROOT / ".venv").resolve())


def bench_rows(stdout):
    """fem_bench's first table: chapter -> (allocations per step, CG iterations)."""
    rows, inside = {}, False
    for line in stdout.splitlines():
        if line.startswith("median ms per step"):
            inside = True
            continue
        if inside and not line.strip():
            if rows:
                break
            continue
        if inside and not line.startswith("chapter"):
            cells = line.split()
            rows[cells[0]] = (float(cells[7]), float(cells[8]))
    return rows


def course_chapter(repo, number):
    """The course's chapter NN (not a variant made for an earlier exercise)."""
    return next(d for d in sorted((repo / "chapters").iterdir())
                if d.name.startswith(number + "_") and (d / "stepper.hpp").exists()
                and not (d / "variant_of").exists())


def readme_has(chapter_dir, command):
    """The README gives the command (NAME as the placeholder), wrapped over lines or not."""
    text = re.sub(r"\s+", " ", (chapter_dir / "README.md").read_text())
    return f"`{command}`" in text


def make_variants(repo, env):
    """Each exercise's variant, made and changed as its README says."""
    for ex in EXERCISES:
        readme_dir = course_chapter(repo, ex.get("readme", ex["chapter"]))
        check(f"{ex['id']}: the README says how to make the variant",
              readme_has(readme_dir, f"./tutorial.sh variant {ex['chapter']} NAME"))
        p = run(repo, f"./tutorial.sh variant {ex['chapter']} {ex['name']}", env)
        if not check(f"{ex['id']}: ./tutorial.sh variant {ex['chapter']} {ex['name']}",
                     p.returncode == 0, p.stdout + p.stderr):
            continue
        for change in ex["change"]:
            file, old, new = change if len(change) == 3 else ("stepper.cpp", *change)
            # Written in the original's names, as the README writes them; the student edits the
            # copy, whose own namespace and includes carry the variant's name.
            original = course_chapter(repo, ex["chapter"]).name
            variant = f"{ex['chapter']}_{ex['name']}"
            old, new = (rewrite(t, original, variant, ex["chapter"]) for t in (old, new))
            source = repo / "chapters" / variant / file
            text = source.read_text()
            check(f"{ex['id']}: the code the exercise changes is there ({file}: {old.strip()[:50]})",
                  old in text, source)
            source.write_text(text.replace(old, new))


def variants_of_every_chapter(repo, chapter_range, env):
    """chapter -> the variant that stands for it (an exercise's, or NN_mine made here), for every
    chapter of the range: a chapter's folder holds more than one source file (stepper and work)."""
    first, last = chapter_range
    originals = [d.name for d in sorted((repo / "chapters").iterdir())
                 if first <= d.name[:2] <= last and (d / "stepper.hpp").exists()
                 and not (d / "variant_of").exists() and len(list(d.glob("*.cpp"))) > 1]
    wanted = {"07_block_sparse", "09_threads", "10_multigrid"}
    check("chapters 07, 09 and 10 have more than one source file",
          {w for w in wanted if first <= w[:2] <= last} <= set(originals), originals)
    run_ids = {ex["id"]: ex for ex in EXERCISES}
    stands_for = {}
    for original in originals:
        ex = run_ids.get(STANDS_FOR.get(original[:2]))
        if ex is not None:
            stands_for[original] = f"{ex['chapter']}_{ex['name']}"
            continue
        p = run(repo, f"./tutorial.sh variant {original[:2]} mine", env)
        if check(f"./tutorial.sh variant {original[:2]} mine", p.returncode == 0, p.stdout + p.stderr):
            stands_for[original] = original[:2] + "_mine"
    return stands_for


def build(repo, env):
    p = run(repo, "cmake --preset release > configure.log 2>&1 && "
                  "cmake --build --preset release --target fem_bench fem_lessons test_every_chapter", env)
    return check("the copy with its variants configures and builds", p.returncode == 0,
                 p.stdout[-3000:] + p.stderr[-3000:] + (repo / "configure.log").read_text()[-2000:]
                 if (repo / "configure.log").exists() else p.stderr)


def check_bench(repo, ex, variant, chapter_dir, env):
    """An exercise's fem_bench command from its README: the variant measured as it must differ."""
    readme_dir = course_chapter(repo, ex.get("readme", ex["chapter"]))
    command = ex["bench"]
    check(f"{ex['id']}: the README gives `{command}`", readme_has(readme_dir, command))
    results_before = sorted((repo / "results").glob("**/*")) if (repo / "results").exists() else []
    p = run(repo, on_test_mesh(command.replace("NAME", ex["name"])), env)
    if not check(f"{ex['id']}: {command} runs", p.returncode == 0, p.stdout + p.stderr):
        return
    rows = bench_rows(p.stdout)
    threaded = ex["expect"] == "threaded rows"
    original = rows.get(chapter_dir.name) or rows.get(chapter_dir.name + "@1")
    changed = rows.get(variant + "@2") if threaded else rows.get(variant) or rows.get(variant + "@1")
    check(f"{ex['id']}: fem_bench measured the variant beside the original",
          original is not None and changed is not None, p.stdout[-2000:])
    if original is None or changed is None:
        return
    for other in ex.get("also", []):
        check(f"{ex['id']}: fem_bench measured {other} beside them",
              other in rows or other + "@1" in rows, sorted(rows))
    if ex["expect"] == "more allocations":
        check(f"{ex['id']}: the variant allocates more per step "
              f"({changed[0]:g} against {original[0]:g})", changed[0] > original[0])
    elif ex["expect"] == "more iterations":
        check(f"{ex['id']}: the variant needs more CG iterations "
              f"({changed[1]:g} against {original[1]:g})", changed[1] > original[1])
    elif threaded:
        check(f"{ex['id']}: the variant ran on 1 and on 2 threads", variant + "@1" in rows, sorted(rows))
        check(f"{ex['id']}: the threaded variant needs the same CG iterations "
              f"({changed[1]:g} against {original[1]:g})", changed[1] == original[1])
    elif ex["expect"] == "same iterations":
        # The same products with their sums in another order: CG's count over
        # hundreds of iterations moves by rounding alone (06/1: 306 against 303).
        check(f"{ex['id']}: the variant needs the same CG iterations, to rounding "
              f"({changed[1]:g} against {original[1]:g})",
              abs(changed[1] - original[1]) <= max(1.0, 0.02 * original[1]))
    after = sorted((repo / "results").glob("**/*")) if (repo / "results").exists() else []
    check(f"{ex['id']}: --no-json wrote no results", after == results_before, after)


def check_lesson(repo, name, command, variant, original, env):
    """A lesson run with --chapter VARIANT: the variant's copy beside the original's, only those."""
    p = run(repo, on_test_mesh(command), env)
    check(f"{name}: `{command}` runs the variant's copy beside the original's",
          p.returncode == 0 and f"### {variant}" in p.stdout and f"### {original}" in p.stdout
          and p.stdout.count("\n### ") == 2, p.stdout[-2000:] + p.stderr[-2000:])


def check_tests(repo, ex, variant, chapter_dir, env):
    """An exercise's `./tutorial.sh test -L chNN_NAME`: the variant's tests, passing or failing."""
    command = ex["test"]
    check(f"{ex['id']}: the README gives `{command}`", readme_has(chapter_dir, command))
    # ./tutorial.sh test builds everything first; the copy built what these tests
    # need, so ctest with the same selection runs them, side by side as it does.
    selection = command.replace("./tutorial.sh test", "").replace("NAME", ex["name"]).strip()
    p = run(repo, f"ctest --preset release -j {os.cpu_count() or 1} {selection}", env)
    ran = re.findall(r"Test +#\d+: (.*?) \.+", p.stdout)
    check(f"{ex['id']}: `{command}` runs the variant's tests and only those",
          len(ran) >= 4 and all(name.startswith(variant + ":") for name in ran), p.stdout[-2000:])
    if ex["test_passes"]:
        check(f"{ex['id']}: the variant's tests pass", p.returncode == 0, p.stdout[-2000:])
    else:
        failed = re.findall(rf"\d+ - ({re.escape(variant)}: .*?) \(Failed\)", p.stdout)
        check(f"{ex['id']}: the variant's tests fail, `{ex['failing']}` among them",
              p.returncode != 0 and any(ex["failing"] in f for f in failed), p.stdout[-2000:])


def check_every_variant(repo, stands_for, out, env):
    """The variant of every chapter passes the generic tests under its own name (an exercise's
    passing `./tutorial.sh test -L chNN_NAME` already ran them), runs beside its original in one
    fem_bench run, and its copy of the chapter's lesson measures it."""
    passed_already = {f"{ex['chapter']}_{ex['name']}" for ex in EXERCISES if ex.get("test_passes")}
    for variant in stands_for.values():
        if variant in passed_already:
            continue
        p = run(repo, f"build/release/tests/test_every_chapter '{variant}:*' --warn NoAssertions", env)
        check(f"{variant} passes the checks every chapter passes",
              p.returncode == 0 and "All tests passed" in p.stdout, p.stdout[-3000:] + p.stderr)
    measured = sorted(list(stands_for) + list(stands_for.values()))
    p = run(repo, "build/release/fem_bench --mesh meshes/test_beam.msh --steps 2 --warmup 1 --threads 1 "
                  f"--no-solvers --chapters {','.join(measured)} --json {out}", env)
    check("fem_bench runs the variants beside their originals", p.returncode == 0, p.stderr)
    rows = json.loads(out.read_text())["chapters"] if out.exists() else []
    names = {r["chapter"].split("@")[0] for r in rows}
    check("the run's JSON holds every original and every variant", set(measured) <= names, sorted(names))
    lessons_run = {(ex["chapter"], ex["lesson"].split()[1]) for ex in EXERCISES if "lesson" in ex}
    for original, variant in stands_for.items():
        lesson = LESSONS.get(original[:2])
        if lesson and (original[:2], lesson) not in lessons_run:
            check_lesson(repo, variant, f"build/release/fem_lessons {lesson} --chapter {variant} --steps 2",
                         variant, original, env)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--keep", type=pathlib.Path, help="work in this folder and keep it")
    parser.add_argument("--only", help="comma-separated exercise ids (e.g. 07/3,10/4): only these, "
                        "without the variants of every chapter")
    parser.add_argument("--chapters", help="FIRST-LAST (e.g. 01-06): only the exercises of these "
                        "chapters' READMEs and the variants of these chapters (ctest runs two "
                        "ranges side by side)")
    args = parser.parse_args()
    chapter_range = ("00", "99")
    if args.chapters:
        first, _, last = args.chapters.partition("-")
        chapter_range = (first, last or first)
        EXERCISES[:] = [ex for ex in EXERCISES if first <= ex["id"][:2] <= (last or first)]
        if not EXERCISES:
            parser.error(f"no exercise in chapters {args.chapters}")
    if args.only:
        wanted = args.only.split(",")
        unknown = [w for w in wanted if w not in {ex["id"] for ex in EXERCISES}]
        if unknown:
            parser.error(f"no exercise {', '.join(unknown)} (known: {', '.join(ex['id'] for ex in EXERCISES)})")
        EXERCISES[:] = [ex for ex in EXERCISES if ex["id"] in wanted]
    with tempfile.TemporaryDirectory() as tmp:
        repo = args.keep or pathlib.Path(tmp) / "clone"
        if repo.exists():
            shutil.rmtree(repo)
        repo.mkdir(parents=True)
        copy_repository(repo)
        env = dict(os.environ, OMP_WAIT_POLICY="passive")
        make_variants(repo, env)
        stands_for = {} if args.only else variants_of_every_chapter(repo, chapter_range, env)
        phase("the copy and its variants")
        if not build(repo, env):
            print(f"{results['passed']} passed, {results['failed']} failed")
            return 1
        phase("the build")
        for ex in EXERCISES:
            variant = f"{ex['chapter']}_{ex['name']}"
            chapter_dir = course_chapter(repo, ex["chapter"])
            if "bench" in ex:
                check_bench(repo, ex, variant, chapter_dir, env)
            if "lesson" in ex:
                command = ex["lesson"]
                check(f"{ex['id']}: the README gives `{command}`", readme_has(chapter_dir, command))
                check_lesson(repo, ex["id"], command.replace("NAME", ex["name"]), variant,
                             chapter_dir.name, env)
            if "test" in ex:
                check_tests(repo, ex, variant, chapter_dir, env)
        phase("the exercises' commands")
        if stands_for:
            check_every_variant(repo, stands_for, pathlib.Path(tmp) / "variants.json", env)
            phase("the variant of every chapter")
    print(f"{results['passed']} passed, {results['failed']} failed")
    return 1 if results["failed"] else 0

if __name__ == "__main__":
    sys.exit(main())
