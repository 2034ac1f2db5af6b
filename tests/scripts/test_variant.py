#!/usr/bin/env python3
"""Tests of ./tutorial.sh variant (fem-tools course variant) on a copy of the chapters: the copy
is made with its namespace and includes renamed and a variant_of file; the build's registry
generator (chapters/registry.cmake) lists it after its original with its title; it compiles
beside the original (the generated registry includes both headers); the generated-diff check
leaves it out; bad requests are refused with the reason. Prints 'N passed, M failed' last.

    test_variant.py --cxx g++ --include /usr/include/eigen3"""
import argparse
import pathlib
import shutil
import subprocess
import sys
import tempfile

from femtools.course import handin as check_handin

ROOT = pathlib.Path(__file__).resolve().parents[2]
results = {"passed": 0, "failed": 0}


def check(name, condition, detail=""):
    results["passed" if condition else "failed"] += 1
    print(f"{'ok  ' if condition else 'FAIL'} {name}{'' if condition else ': ' + str(detail)[:3000]}")


def run(*args, cwd=None):
    return subprocess.run([str(a) for a in args], capture_output=True, text=True, cwd=cwd)


def copy_repo(tmp):
    """The parts of the repository the variant, the registry and the diffs need, without the
    student's own variants of the working tree."""
    def ignore(directory, names):
        return {n for n in names if n == "__pycache__" or (pathlib.Path(directory) / n / "variant_of").exists()}
    repo = tmp / "repo"
    for part in ("chapters", "common", "tools", "docs/diffs"):
        shutil.copytree(ROOT / part, repo / part, ignore=ignore)
    return repo


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--cxx", default="c++")
    parser.add_argument("--include", action="append", default=[], help="include directories")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        repo = copy_repo(pathlib.Path(tmp))
        make = [sys.executable, "-m", "femtools", "course", "variant", "--root", repo]
        # The copy's diffs made current first, so that the check below is about the variant
        # alone (the repository's own diffs have their own test).
        run(sys.executable, "-m", "femtools", "docs", "diffs", "--root", repo)

        p = run(*make, "06", "my_fused_updates")
        check("fem-tools course variant 06 my_fused_updates exits 0", p.returncode == 0, p.stderr)
        check("its next steps name the copy's sources, the variant's own test label and the "
              "diff by name", "stepper.cpp, stepper.hpp" in p.stdout
              and "test -L ch06_my_fused_updates" in p.stdout and "--no-solvers" in p.stdout
              and "diff my_fused_updates" in p.stdout and "edit chapters/" not in p.stdout, p.stdout)
        variant = repo / "chapters" / "06_my_fused_updates"
        check("the copy has the original's files",
              sorted([f.name for f in (repo / "chapters" / "06_custom_pcg").iterdir()] + ["variant_of"])
              == sorted(f.name for f in variant.iterdir()), list(variant.iterdir()))
        check("variant_of names the original",
              (variant / "variant_of").read_text().strip() == "06_custom_pcg")
        hpp, cpp = (variant / "stepper.hpp").read_text(), (variant / "stepper.cpp").read_text()
        check("the namespace is renamed", "namespace fem::ch06_my_fused_updates {" in hpp
              and "fem::ch06 " not in hpp and "ch06::" not in cpp, hpp[:2000])
        check("the copy includes its own header", '#include "chapters/06_my_fused_updates/stepper.hpp"' in cpp
              and "chapters/06_custom_pcg/" not in cpp)
        check("the README's heading names the variant and its original",
              (variant / "README.md").read_text().startswith(
                  "# Chapter 06_my_fused_updates: a variant of 06_custom_pcg ("))

        # The hand-in: the variant's change against its original with the copy's renames undone.
        p = run(sys.executable, "-m", "femtools", "docs", "diffs", "--root", repo, "--variant",
                "06_my_fused_updates")
        check("an unchanged variant's diff is empty (renames undone)", p.returncode == 0
              and p.stdout == "", p.stdout[:2000] + p.stderr)
        (variant / "stepper.cpp").write_text(cpp.replace("namespace {", "namespace {  // changed", 1))
        p = run(sys.executable, "-m", "femtools", "docs", "diffs", "--root", repo, "--variant",
                "06_my_fused_updates")
        check("a one-line change is one hunk of one line", p.returncode == 0
              and p.stdout.count("\n@@") + p.stdout.startswith("@@") == 1
              and p.stdout.count("\n+namespace {  // changed") == 1, p.stdout[:2000] + p.stderr)
        check("its context reads in the original's names, not the copy's",
              "ch06_my_fused_updates" not in p.stdout and "06_my_fused_updates/" not in
              p.stdout.split("\n@@")[-1], p.stdout[:2000])
        by_name = run(sys.executable, "-m", "femtools", "docs", "diffs", "--root", repo,
                      "--variant", "my_fused_updates")
        check("a variant answers to its name alone", by_name.stdout == p.stdout, by_name.stderr)
        nothing = run(sys.executable, "-m", "femtools", "docs", "diffs", "--root", repo,
                      "--variant", "no_such_variant")
        check("an unknown variant is refused with the known ones", nothing.returncode != 0
              and "06_my_fused_updates" in nothing.stderr, nothing.stderr)
        (variant / "stepper.cpp").write_text(cpp)

        # Refusals, with the reason.
        for bad, reason in ((["06", "my_fused_updates"], "exists already"),
                            (["99", "x"], "no chapter 99"),
                            (["06", "Bad-Name"], "not a variant name")):
            p = run(*make, *bad)
            check(f"fem-tools course variant {' '.join(bad)} is refused ({reason})",
                  p.returncode == 2 and reason in p.stderr, p.stderr)

        p = run(ROOT / "tutorial.sh", "variant", "06")
        check("./tutorial.sh variant without a name prints its usage and exits 2",
              p.returncode == 2 and "usage: ./tutorial.sh variant NN NAME" in p.stderr, p.stderr)

        # The registry the build would generate.
        # The two lists: the steppers (the library's) and the course's hooks by id.
        generated, course = repo / "chapter_list.cpp", repo / "course_list.cpp"
        outputs = [f"-DOUTPUT={generated}", f"-DCOURSE_OUTPUT={course}"]
        p = run("cmake", f"-DSOURCE_DIR={repo}", *outputs, "-P", repo / "chapters" / "registry.cmake")
        check("registry.cmake generates the lists",
              p.returncode == 0 and generated.exists() and course.exists(), p.stderr)
        text = generated.read_text() if generated.exists() else ""
        hooks = course.read_text() if course.exists() else ""
        check("the variant is registered with its original",
              'chapter<fem::ch06_my_fused_updates::CustomPcgStepper>("06_my_fused_updates", '
              '"a variant of 06_custom_pcg (our own preconditioned conjugate gradient)", "06_custom_pcg"'
              in text, text)
        check("the originals keep their entries",
              'chapter<fem::ch06::CustomPcgStepper>("06_custom_pcg"' in text
              and 'chapter<fem::ch01::NaiveStepper>("01_naive", "the naive stepper", "",' in text, text)
        check("the course list names each chapter's hooks, the variant's too",
              'course<fem::ch01::NaiveStepper>("01_naive", nullptr)' in hooks
              and 'course<fem::ch08::ElementKernelsStepper>("08_element_kernels", &fem::ch08::lessons)'
              in hooks and '"06_my_fused_updates"' in hooks, hooks)
        # Each entry ends with the hash of its chapter's sources, as the hand-in check computes it.
        check("each entry records its chapter's source hash",
              f'"{check_handin.source_hash(variant)}"' in text
              and f'"{check_handin.source_hash(repo / "chapters" / "01_naive")}"' in text, text[-1500:])

        # Original and variant compile side by side (no clash of names), the variant's own file too.
        flags = ["-std=c++17", "-fsyntax-only", f"-I{repo}", *[f"-I{i}" for i in args.include],
                 "-DFEM_SOURCE_DIR=\"/\""]
        for source in (generated, course, variant / "stepper.cpp"):
            p = run(args.cxx, *flags, source)
            check(f"{source.name} of the variant compiles", p.returncode == 0, p.stderr)

        # A malformed chapter stops the generator with the file and the rule.
        broken = repo / "chapters" / "08_broken"
        broken.mkdir()
        (broken / "stepper.hpp").write_text("namespace fem::ch08 {\nstruct Nothing {};\n}\n")
        (broken / "README.md").write_text("# Chapter 08: broken\n")
        p = run("cmake", f"-DSOURCE_DIR={repo}", *outputs, "-P", repo / "chapters" / "registry.cmake")
        check("a chapter without a stepper class is refused with the rule",
              p.returncode != 0 and "chapters/08_broken" in p.stderr and "public Stepper" in p.stderr,
              p.stderr)
        shutil.rmtree(broken)

        # The generated-diff check ignores the variant (and still checks the course's chapters).
        p = run(sys.executable, "-m", "femtools", "docs", "diffs", "--check", "--root", repo)
        check("fem-tools docs diffs --check leaves the variant out", p.returncode == 0, p.stderr)
        (repo / "chapters" / "07_block_sparse" / "stepper.cpp").write_text("// changed\n")
        p = run(sys.executable, "-m", "femtools", "docs", "diffs", "--check", "--root", repo)
        check("fem-tools docs diffs --check still catches a changed chapter", p.returncode == 1, p.stdout)

    print(f"{results['passed']} passed, {results['failed']} failed")
    return 1 if results["failed"] else 0


if __name__ == "__main__":
    sys.exit(main())
