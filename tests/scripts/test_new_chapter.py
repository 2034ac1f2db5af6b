#!/usr/bin/env python3
"""Adding a chapter is adding a folder: in a copy of the repository, the last chapter copied
under the next number (its namespace, includes, id and heading renamed, nothing else edited)
builds, passes the checks every chapter passes, runs in fem_bench, is counted by the roofline
from its own data (its rows' counts equal the original's: the same code on the same mesh), and
appears in the generated docs tables (the chapter files and the phase owners of
chapters/README.md, its diff in docs/diffs/). Prints 'N passed, M failed' last.

    test_new_chapter.py --venv .venv   # builds a copy: the new chapter's files, the rest from ccache"""
import argparse
import hashlib
import json
import pathlib
import re
import shutil
import subprocess
import sys
import tempfile

from test_exercises import ROOT, check, results


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
    # ccache serves every file the new chapter leaves unchanged from the original's build.
    (repo / ".venv").symlink_to(pathlib.Path(venv).resolve())
    return repo


PHASES = ("forces", "dfdx", "compose", "constraints", "solve")


def last_chapter(repo):
    return max(d for d in (repo / "chapters").iterdir()
               if d.is_dir() and d.name[:2].isdigit() and (d / "stepper.hpp").exists()
               and not (d / "variant_of").exists())


def copy_chapter(original, number):
    """chapters/NN_name copied as chapters/MM_name: the chapter's names renamed, as a person
    starting the next chapter from the last one would."""
    old, new = original.name[:2], f"{number:02d}"
    target = original.parent / (new + original.name[2:])
    target.mkdir()
    for source in sorted(p for p in original.iterdir() if p.is_file()):
        text = source.read_text().replace(original.name, target.name)
        text = re.sub(rf"\bch{old}\b", f"ch{new}", text)
        text = re.sub(rf"\bChapter {old}\b", f"Chapter {new}", text)
        (target / source.name).write_text(text)
    return target


def tree_hashes(repo):
    return {str(p.relative_to(repo)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in repo.rglob("*") if p.is_file() and "build" not in p.relative_to(repo).parts
            and "__pycache__" not in p.parts and ".venv" not in p.relative_to(repo).parts}


def table_rows(text, marker):
    body = re.search(rf"<!-- {marker}:begin -->(.*?)<!-- {marker}:end -->", text, re.S)
    return [line.split("|")[1].strip() for line in (body.group(1) if body else "").splitlines()
            if line.startswith("| ")]


def roofline_counts(stdout, chapter):
    """Per phase, the columns of the chapter's roofline rows that count work (MB read, written,
    Mflop, flop/byte, working set): not times."""
    rows = [line.split("|") for line in stdout.splitlines() if line.startswith(f"| `{chapter}@")]
    return {r[2].strip(): [c.strip() for c in r[3:8]] for r in rows if r[2].strip() in PHASES}


def build_and_run(repo, new, original, tmp):
    build = repo / "build" / "release"
    p = run("cmake", "--preset", "release", cwd=repo)
    check("the copy configures with the new chapter", p.returncode == 0, p.stdout + p.stderr)
    p = run("cmake", "--build", build, "--target", "fem_bench", "fem_lessons", "test_every_chapter")
    check("the copy builds with the new chapter", p.returncode == 0, p.stdout + p.stderr)
    if p.returncode != 0:
        return
    p = run(build / "tests" / "test_every_chapter", f"{new}:*", "--warn", "NoAssertions")
    check(f"{new} passes the checks every chapter passes",
          p.returncode == 0 and "All tests passed" in p.stdout, p.stdout + p.stderr)
    out = tmp / "bench.json"
    p = run(build / "fem_bench", "--mesh", repo / "meshes" / "test_beam.msh", "--steps", "2", "--warmup", "1",
            "--threads", "1", "--no-solvers", "--chapters", f"{original},{new}", "--json", out)
    rows = json.loads(out.read_text())["chapters"] if out.exists() else []
    check(f"fem_bench runs {new} beside {original}",
          p.returncode == 0 and new in {r["chapter"].split("@")[0] for r in rows}, p.stderr)
    p = run(build / "fem_lessons", "roofline", "--mesh", repo / "meshes" / "test_beam.msh", "--steps", "2",
            "--warmup", "1", "--roof-seconds", "0.02", "--no-likwid", "--threads-max", "1", "--meshes", "",
            "--chapters", f"{original},{new}", cwd=repo)
    counts, reference = roofline_counts(p.stdout, new), roofline_counts(p.stdout, original)
    check(f"the roofline counts {new} from its own data, as {original} (the same code)",
          p.returncode == 0 and {"forces", "solve"} <= set(counts) and counts == reference,
          f"{counts} against {reference}\n{p.stderr[-2000:]}")


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--venv", default=str(pathlib.Path(__file__).resolve().parents[2] / ".venv"))
    parser.add_argument("--keep", help="build in this folder and keep it")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(args.keep) if args.keep else pathlib.Path(tmp)
        repo = copy_repo(tmp, args.venv)
        before = tree_hashes(repo)
        original = last_chapter(repo)
        added = copy_chapter(original, int(original.name[:2]) + 1)
        after = tree_hashes(repo)
        changed = sorted(f for f in set(before) | set(after) if before.get(f) != after.get(f))
        check(f"{added.name} is a new folder and nothing else",
              all(f.startswith(f"chapters/{added.name}/") for f in changed) and changed, changed)
        build_and_run(repo, added.name, original.name, tmp)
        p = run(sys.executable, "-m", "femtools", "docs", "diffs", "--root", repo)
        # The phase-owners table is the program's, from the recipes (as ./tutorial.sh docs).
        owners = run(repo / "build" / "release" / "fem_lessons", "phase-owners", "--write",
                     repo / "chapters" / "README.md")
        p.returncode = p.returncode or owners.returncode
        p.stdout += owners.stdout
        p.stderr += owners.stderr
        readme = (repo / "chapters" / "README.md").read_text()
        number = added.name[:2]
        check(f"the generated docs tables have a row for chapter {number}",
              p.returncode == 0 and number in table_rows(readme, "chapter-files")
              and number in table_rows(readme, "phase-owners")
              and (repo / "docs" / "diffs" / f"{added.name}.diff").exists(), p.stdout + p.stderr)
    print(f"{results['passed']} passed, {results['failed']} failed")
    return 1 if results["failed"] else 0


if __name__ == "__main__":
    sys.exit(main())
