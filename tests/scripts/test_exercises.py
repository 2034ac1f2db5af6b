#!/usr/bin/env python3
"""The exercises of chapters 01-12 as a student does them: in a copy of the repository (the
current files, committed or not), make each code-changing exercise's variant with
`./tutorial.sh variant`, apply a small scripted version of the exercise's change, build, and
run the commands the chapter README gives, checking that

  - each command is written in the README as run here (NAME replaced by the variant's name),
  - it succeeds, or fails where the exercise says a test fails (a fem_bench or fem_lessons
    command on the test mesh where the README leaves the mesh to the poster-sized default:
    on_test_mesh),
  - and it measured the variant, not the original: the variant's row is in fem_bench's table
    and differs from the original's as the change must make it differ.

Not covered: 03/3 (a debug build), the exercises that change no code, and those whose change
is a design of the student's own (a new smoother, float storage, a SIMD kernel). Prints 'N
passed, M failed' last; about ten minutes on 2 cores (one build of every chapter and eleven
variants).

    test_exercises.py [--keep DIR] [--only 07/3,10/4]"""
import argparse
import os
import pathlib
import re
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
    return condition


# The exercises: chapter, variant name, the text replaced in the variant's files (the scripted
# change: (old, new) in stepper.cpp, or (file, old, new)), and the README commands to run (NAME
# stands for the variant's name).
EXERCISES = [
    {"id": "01/2", "chapter": "01", "name": "ex_setzero",
     "change": [("dfdx_.coeffs().setZero();", "dfdx_.setZero();")],
     "bench": "build/release/fem_bench --chapters 01,01_NAME --mesh meshes/test_beam.msh --steps 5 --warmup 1 --no-solvers --no-json",
     "expect": "more allocations",
     "test": "./tutorial.sh test -L ch01_NAME", "test_passes": True},
    {"id": "02/1", "chapter": "02", "name": "ex_alias",
     "change": [("b_.noalias() = h * (dfdx_ * scaled_v_);", "b_ = h * (dfdx_ * scaled_v_);")],
     "bench": "build/release/fem_bench --chapters 02,02_NAME --mesh meshes/test_beam.msh --steps 5 --no-solvers --no-json",
     "expect": "more allocations"},
    {"id": "05/1", "chapter": "05", "name": "ex_nodiag",
     "change": [("block(A_, c.node, diagonal_block_[c.node]) += Eigen::Matrix3d::Identity() - c.filter;",
                 "(void)diagonal_block_;")],
     "test": "./tutorial.sh test -L ch05_NAME", "test_passes": False,
     "failing": "constrained velocities are the prescribed ones"},
    {"id": "06/1", "chapter": "06", "name": "ex_colmajor",
     "change": [("q.noalias() = A.transpose() * y;", "q.noalias() = A * y;"),
                ("q.noalias() = A.transpose() * p;", "q.noalias() = A * p;")],
     "bench": "build/release/fem_bench --chapters 06,06_NAME --steps 30 --no-solvers --no-json",
     "expect": "same iterations"},
    {"id": "06/2", "chapter": "06", "name": "ex_cold",
     "change": [("  // Warm start: y_ still holds the previous step's answer; pcg_solve filters it.\n",
                 "  y_.setZero();  // the warm start off\n")],
     "bench": "build/release/fem_bench --chapters 06,06_NAME --steps 30 --no-solvers --no-json",
     "expect": "more iterations"},
    {"id": "06/3", "chapter": "06", "name": "ex_nofilter",
     "change": [("      r -= step * q;\n      filter(constraints, r);\n", "      r -= step * q;\n"),
                ("      s = inverse_diagonal.cwiseProduct(r);\n      filter(constraints, s);\n",
                 "      s = inverse_diagonal.cwiseProduct(r);\n")],
     "test": "./tutorial.sh test -L ch06_NAME", "test_passes": False,
     "failing": "constrained velocities are the prescribed ones"},
    {"id": "07/2", "chapter": "07", "name": "ex_scalar_jacobi",
     "change": [("block_pcg.cpp", "inverse_diagonal[i] = A.blocks[diagonal_block[i]].inverse();",
                 "inverse_diagonal[i] = A.blocks[diagonal_block[i]].diagonal().cwiseInverse().asDiagonal();")],
     "bench": "build/release/fem_bench --chapters 07,07_NAME --steps 30 --no-solvers --no-json",
     "expect": "more iterations"},
    {"id": "07/3", "chapter": "07", "name": "ex_threads",
     "change": [("block_sparse.hpp", "    multiply_rows(x, y, 0, block_rows());\n",
                 "#pragma omp parallel for schedule(static)\n"
                 "    for (int i = 0; i < block_rows(); ++i) multiply_rows(x, y, i, i + 1);\n"),
                ("stepper.hpp", "  const StepProfile& profile() const override { return profile_; }\n",
                 "  const StepProfile& profile() const override { return profile_; }\n"
                 "  bool uses_threads() const override { return true; }\n")],
     "bench": "build/release/fem_bench --chapters 07,07_NAME --threads 1,2 --steps 30 --no-solvers --no-json",
     "expect": "threaded rows"},
    {"id": "08/1", "chapter": "08", "name": "ex_last_rotation",
     "change": [("element_kernels.cpp",
                 "Eigen::Quaterniond q = predicted_rotation(rotations_[e], previous_rotations_[e]);",
                 "Eigen::Quaterniond q = rotations_[e];")],
     "bench": "build/release/fem_bench --chapters 08,08_NAME --steps 30 --no-solvers --no-json",
     "expect": "same iterations"},
    {"id": "09/2", "chapter": "09", "name": "ex_reduction",
     "change": [("parallel_pcg.cpp",
                 "  for (const int c : StaticShare(chunks_.count())) {\n"
                 "    A.multiply_rows(p_, q_, chunks_.start[c], chunks_.start[c + 1]);\n"
                 "    partial_pq_[c] = p_.segment(chunks_.first_dof(c), chunks_.dofs(c))\n"
                 "                         .dot(q_.segment(chunks_.first_dof(c), chunks_.dofs(c)));\n"
                 "  }\n"
                 "  return sum_in_order(partial_pq_);\n",
                 "  static double pq;  // shared by the team, as an orphaned reduction needs\n"
                 "#pragma omp single\n"
                 "  pq = 0.0;\n"
                 "#pragma omp for schedule(static) reduction(+ : pq)\n"
                 "  for (int c = 0; c < chunks_.count(); ++c) {\n"
                 "    A.multiply_rows(p_, q_, chunks_.start[c], chunks_.start[c + 1]);\n"
                 "    pq += p_.segment(chunks_.first_dof(c), chunks_.dofs(c))\n"
                 "              .dot(q_.segment(chunks_.first_dof(c), chunks_.dofs(c)));\n"
                 "  }\n"
                 "  return pq;\n")],
     "test": "./tutorial.sh test -L ch09_NAME", "test_passes": False,
     "failing": "the same state to the last bit on 1, 2 and 3 threads"},
    {"id": "10/4", "chapter": "10", "name": "ex_yardstick",
     "change": [("refresh_rule.cpp",
                 "    measure_next_ = false;\n  }\n",
                 "    measure_next_ = false;\n  } else if (!measure_next_) {\n"
                 "    cycles_after_refresh_ = std::min(cycles_after_refresh_, last);\n  }\n")],
     "bench": "build/release/fem_bench --chapters 10,10_NAME --steps 30 --no-solvers --no-json",
     "expect": "measured",
     "lesson": "build/release/fem_lessons multigrid --chapter 10_NAME"},
    # Written in chapter 10's README, done in a variant of chapter 09 and measured beside both.
    {"id": "10/5", "chapter": "09", "readme": "10", "name": "ex_guess",
     "change": [("stepper.hpp", "  long long steps_taken_ = 0;\n",
                 "  long long steps_taken_ = 0;\n"
                 "  Eigen::VectorXd previous_, before_previous_;  // y_(n-1), y_(n-2)\n"),
                ("  // Warm start: y_ still holds the previous step's answer; the solver filters it.\n",
                 "  if (previous_.size() != y_.size()) previous_ = before_previous_ = y_;\n"
                 "  for (Eigen::Index k = 0; k < y_.size(); ++k) {\n"
                 "    const double last = y_[k];\n"
                 "    y_[k] = 3.0 * last - 3.0 * previous_[k] + before_previous_[k];\n"
                 "    before_previous_[k] = previous_[k];\n"
                 "    previous_[k] = last;\n"
                 "  }\n")],
     "bench": "build/release/fem_bench --chapters 09,09_NAME,10 --steps 30 --no-solvers --no-json",
     "expect": "measured", "also": ["10_multigrid"]},
    {"id": "11/2", "chapter": "11", "name": "ex_slabs",
     "change": [("stepper.hpp", "static constexpr int kSlabs = 64;", "static constexpr int kSlabs = 8;")],
     "bench": "build/release/fem_bench --chapters 11,11_NAME --threads 1,2 --steps 30 --no-solvers --no-json",
     "expect": "measured",
     "lesson": "build/release/fem_lessons node-order --chapter 11_NAME"},
    {"id": "12/1", "chapter": "12", "name": "ex_widened",
     "change": [("stepper.hpp", "Arithmetic arithmetic = Arithmetic::single,",
                 "Arithmetic arithmetic = Arithmetic::double_on_float,")],
     "bench": "build/release/fem_bench --chapters 12,12_NAME --threads 1,2 --steps 30 --no-solvers --no-json",
     "expect": "measured"},
    {"id": "12/2", "chapter": "12", "name": "ex_unpadded",
     "change": [("reduced_kernels.hpp",
                 "  using Column = Eigen::Matrix<float, kPaddedColumn<R>, 1>;\n  for (int j = 0; j < C; ++j)\n"
                 "    sums.of(j) += Eigen::Map<const Column>(M.data() + R * j).template cast<Real>() * x[j];\n",
                 "  for (int j = 0; j < C; ++j)\n"
                 "    sums.of(j).template head<R>() += M.col(j).template cast<Real>() * x[j];\n")],
     "bench": "build/release/fem_bench --chapters 12,12_NAME --steps 30 --no-solvers --no-json",
     "expect": "measured",
     "lesson": "build/release/fem_lessons half-the-bytes --chapter 12_NAME --steps 10"},
    {"id": "12/4", "chapter": "12", "name": "ex_lanes",
     "change": [("batch_rotations.hpp", "constexpr int kLanes = 8;", "constexpr int kLanes = 4;")],
     "bench": "build/release/fem_bench --chapters 12,12_NAME --steps 30 --no-solvers --no-json",
     "expect": "measured",
     "lesson": "build/release/fem_lessons batched-elements --chapter 12_NAME"},
]


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


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--keep", type=pathlib.Path, help="work in this folder and keep it")
    parser.add_argument("--only", help="comma-separated exercise ids (e.g. 07/3,10/4): only these")
    parser.add_argument("--chapters", help="FIRST-LAST (e.g. 01-06): only the exercises of these "
                        "chapters' READMEs (ctest runs two ranges side by side)")
    args = parser.parse_args()
    if args.chapters:
        first, _, last = args.chapters.partition("-")
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

        # The variants, made and changed as the READMEs say.
        originals = {}
        for ex in EXERCISES:
            # The course's chapter, not a variant made for an earlier exercise (a variant's name
            # can sort before its original's: 12_ex_lanes before 12_half_the_bytes).
            chapter_dir = next(d for d in sorted((repo / "chapters").iterdir())
                               if d.name.startswith(ex["chapter"] + "_") and (d / "stepper.hpp").exists()
                               and not (d / "variant_of").exists())
            originals[ex["chapter"]] = chapter_dir
            readme_dir = course_chapter(repo, ex.get("readme", ex["chapter"]))
            check(f"{ex['id']}: the README says how to make the variant",
                  readme_has(readme_dir, f"./tutorial.sh variant {ex['chapter']} NAME"))
            p = run(repo, f"./tutorial.sh variant {ex['chapter']} {ex['name']}", env)
            if not check(f"{ex['id']}: ./tutorial.sh variant {ex['chapter']} {ex['name']}",
                         p.returncode == 0, p.stdout + p.stderr):
                continue
            for change in ex["change"]:
                file, old, new = change if len(change) == 3 else ("stepper.cpp", *change)
                source = repo / "chapters" / f"{ex['chapter']}_{ex['name']}" / file
                text = source.read_text()
                check(f"{ex['id']}: the code the exercise changes is there ({file}: {old.strip()[:50]})",
                      old in text, source)
                source.write_text(text.replace(old, new))

        p = run(repo, "cmake --preset release > configure.log 2>&1 && "
                      "cmake --build --preset release --target fem_bench fem_lessons test_every_chapter", env)
        if not check("the copy with its variants configures and builds", p.returncode == 0,
                     p.stdout[-3000:] + p.stderr[-3000:] + (repo / "configure.log").read_text()[-2000:]
                     if (repo / "configure.log").exists() else p.stderr):
            print(f"{results['passed']} passed, {results['failed']} failed")
            return 1

        for ex in EXERCISES:
            variant = f"{ex['chapter']}_{ex['name']}"
            chapter_dir = originals[ex["chapter"]]
            readme_dir = course_chapter(repo, ex.get("readme", ex["chapter"]))
            if "bench" in ex:
                command = ex["bench"]
                check(f"{ex['id']}: the README gives `{command}`", readme_has(readme_dir, command))
                results_before = sorted((repo / "results").glob("**/*")) if (repo / "results").exists() else []
                p = run(repo, on_test_mesh(command.replace("NAME", ex["name"])), env)
                if not check(f"{ex['id']}: {command} runs", p.returncode == 0, p.stdout + p.stderr):
                    continue
                rows = bench_rows(p.stdout)
                threaded = ex["expect"] == "threaded rows"
                original = rows.get(chapter_dir.name) or rows.get(chapter_dir.name + "@1")
                changed = rows.get(variant + "@2") if threaded else rows.get(variant) or rows.get(variant + "@1")
                check(f"{ex['id']}: fem_bench measured the variant beside the original",
                      original is not None and changed is not None, p.stdout[-2000:])
                if original is None or changed is None:
                    continue
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
                    check(f"{ex['id']}: the variant ran on 1 and on 2 threads",
                          variant + "@1" in rows, sorted(rows))
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
            if "lesson" in ex:
                command = ex["lesson"]
                check(f"{ex['id']}: the README gives `{command}`", readme_has(chapter_dir, command))
                p = run(repo, on_test_mesh(command.replace("NAME", ex["name"])), env)
                check(f"{ex['id']}: `{command}` runs the variant's copy beside the original's",
                      p.returncode == 0 and f"### {variant}" in p.stdout and
                      f"### {chapter_dir.name}" in p.stdout, p.stdout[-2000:] + p.stderr[-2000:])
            if "test" in ex:
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
                          p.returncode != 0 and any(ex["failing"] in f for f in failed),
                          p.stdout[-2000:])
    print(f"{results['passed']} passed, {results['failed']} failed")
    return 1 if results["failed"] else 0


if __name__ == "__main__":
    sys.exit(main())
