#!/usr/bin/env python3
"""An output path that exists and is not a regular file is refused with its cause, before the
work, and left as it was (common/atomic_file.hpp's not_a_regular_file): a FIFO (whose open
would block until a reader comes) and a symbolic link to /dev/null (a character device, which
the rename would replace as root; the link stands in for the device, so that a broken check
replaces a link, never the system's /dev/null). Every program that writes a result file:
fem_bench --json (with and without --replace, whose refusal must not suggest --replace),
fem_lessons --json, fem_viewer --report and --screenshot. Each run is bounded: a hang fails.
Prints 'N passed, M failed' last.

    test_output_targets.py --bench build/release/fem_bench --lessons build/release/fem_lessons"""
import argparse
import os
import pathlib
import stat
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parents[2]
MESH = ROOT / "meshes" / "test_beam.msh"
results = {"passed": 0, "failed": 0}


def check(name, condition, detail=""):
    results["passed" if condition else "failed"] += 1
    print(f"{'ok  ' if condition else 'FAIL'} {name}{'' if condition else ': ' + str(detail)[:3000]}")


def run(*args):
    try:
        return subprocess.run([str(a) for a in args], capture_output=True, text=True, timeout=60,
                              stdin=subprocess.DEVNULL)
    except subprocess.TimeoutExpired as e:
        return subprocess.CompletedProcess(e.cmd, "timeout", "", "hung for 60 s")


def targets(tmp):
    fifo = tmp / "fifo"
    os.mkfifo(fifo)
    null = tmp / "null"
    null.symlink_to("/dev/null")
    return [(fifo, "a FIFO (named pipe), not a regular file"),
            (null, "a character device, not a regular file")]


def untouched(path):
    mode = os.lstat(path).st_mode
    return stat.S_ISFIFO(mode) or (stat.S_ISLNK(mode) and os.readlink(path) == "/dev/null")


def refused(name, p, path, cause, replace_hint=True):
    text = p.stdout + p.stderr
    check(f"{name}: refused with its cause, rc 2", p.returncode == 2 and cause in text, f"rc {p.returncode}: {text}")
    check(f"{name}: the target is as it was", untouched(path))
    if not replace_hint:
        check(f"{name}: no advice to --replace it", "--replace" not in text and "--no-json" in text, text)


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--bench", required=True)
    parser.add_argument("--lessons", required=True)
    parser.add_argument("--viewer", help="fem_viewer, where it was built")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        for path, cause in targets(tmp):
            for extra in ([], ["--replace"]):
                p = run(args.bench, "--mesh", MESH, "--chapters", "01", "--steps", "1", "--warmup", "1",
                        "--no-solvers", "--json", path, *extra)
                refused(f"fem_bench --json {path.name} {' '.join(extra)}", p, path, cause, replace_hint=False)
            p = run(args.lessons, "spmv", "--mesh", MESH, "--steps", "1", "--json", path)
            refused(f"fem_lessons spmv --json {path.name}", p, path, cause)
            if args.viewer:
                for option in ("--report", "--screenshot"):
                    p = run(args.viewer, "--mesh", MESH, "--frames", "2", option, path)
                    refused(f"fem_viewer {option} {path.name}", p, path, cause)
    print(f"{results['passed']} passed, {results['failed']} failed")
    return 1 if results["failed"] or not results["passed"] else 0


if __name__ == "__main__":
    sys.exit(main())
