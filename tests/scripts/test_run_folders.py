#!/usr/bin/env python3
"""A run's folder belongs to one run, and its results are written whole or not at all
(common/run_lock.hpp, common/atomic_file.hpp), through the programs as a user runs them:
fem_bench and fem_sim into a folder another run is writing are refused before any work,
naming it; --replace replaces a finished run only and says so only then; a write that fails
(FEM_FAIL_WRITES, a full disk injected) exits non-zero with the path and the cause and
leaves the folder byte-identical; Ctrl-C keeps fem_sim's frames so far and names them, and
stops fem_bench with its folder as it was; fem_viewer checks its output files before the work; a run of more than a minute says how long before it goes on,
and its lines reach a file. Prints 'N passed, M failed' last.

    test_run_folders.py --bench build/release/fem_bench --sim build/release/fem_sim"""
import argparse
import os
import pathlib
import re
import signal
import subprocess
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parents[2]
MESH = ROOT / "meshes" / "test_beam.msh"
results = {"passed": 0, "failed": 0}


def check(name, condition, detail=""):
    results["passed" if condition else "failed"] += 1
    print(f"{'ok  ' if condition else 'FAIL'} {name}{'' if condition else ': ' + str(detail)[:3000]}")


def run(*args, env=None):
    return subprocess.run([str(a) for a in args], capture_output=True, text=True,
                          env={**os.environ, **(env or {})}, timeout=600)


def snapshot(folder):
    return {p.name: p.read_bytes() if p.is_file() else "(a folder)" for p in sorted(pathlib.Path(folder).iterdir())}


def wait_for(path, text="", seconds=120):
    """Waits until the file exists (and holds text); False on timeout."""
    end = time.time() + seconds
    while time.time() < end:
        if path.exists() and text in path.read_text(errors="replace"):
            return True
        time.sleep(0.2)
    return False


def holder(args, log):
    """A long run in the background, its output to a file: the run another one meets."""
    return subprocess.Popen([str(a) for a in args], stdout=log, stderr=subprocess.STDOUT)


def second_run_refused(name, first_args, second_args, folder, tmp):
    with open(tmp / f"{name}.log", "w") as log:
        first = holder(first_args, log)
        try:
            locked = wait_for(folder / ".fem_run.lock", "pid")
            p = run(*second_args)
            check(f"{name}: a second run into the folder is refused (exit 2)", locked and p.returncode == 2,
                  p.stdout + p.stderr)
            check(f"{name}: the refusal names the first run (its pid)",
                  f"pid {first.pid}" in p.stderr and "in use by another run" in p.stderr, p.stderr)
        finally:
            first.kill()
            first.wait()


def bench_cases(bench, tmp):
    base = [bench, "--mesh", MESH, "--chapters", "01", "--no-solvers", "--warmup", "1"]
    folder = tmp / "bench_run"
    second_run_refused("fem_bench", base + ["--steps", "1000000", "--out", folder],
                       base + ["--steps", "2", "--out", folder, "--replace"], folder, tmp)
    # The killed run's lock file stays behind: stale, taken over.
    p = run(*base, "--steps", "2", "--out", folder)
    check("fem_bench: a lock left by a run that is gone is taken over",
          p.returncode == 0 and "taken over" in p.stdout, p.stdout + p.stderr)
    check("fem_bench: a new run does not claim to replace anything", "replac" not in p.stdout, p.stdout)
    p = run(*base, "--steps", "2", "--out", folder)
    check("fem_bench: a finished run is not replaced without --replace",
          p.returncode == 2 and "holds an earlier run" in p.stderr, p.stderr)
    (folder / "phases.png").write_bytes(b"the earlier run's plot")
    before = snapshot(folder)
    p = run(*base, "--steps", "2", "--out", folder, "--replace", env={"FEM_FAIL_WRITES": "bench.json"})
    check("fem_bench: a failed write exits non-zero, naming the path and the cause",
          p.returncode == 1 and f"cannot write '{folder / 'bench.json'}': No space left" in p.stderr,
          p.stdout + p.stderr)
    check("fem_bench: ... and does not say 'wrote'", "wrote" not in p.stdout, p.stdout)
    check("fem_bench: the folder a failed write touched is byte-identical", snapshot(folder) == before,
          sorted(snapshot(folder)))
    p = run(*base, "--steps", "2", "--out", folder, "--replace")
    check("fem_bench: --replace replaces a finished run and says so",
          p.returncode == 0 and "(--replace: replaced the run that was there, and its plots)" in p.stdout,
          p.stdout + p.stderr)
    check("fem_bench: no temporary or lock file left", sorted(snapshot(folder)) == ["bench.json"],
          sorted(snapshot(folder)))
    bench_interrupted_case(base, folder, tmp)


def bench_interrupted_case(base, folder, tmp):
    """Ctrl-C (or a batch system's SIGTERM, while it measures: after the mesh load, which can
    reset its handler) during --replace: the run stops after its step with a message, exit
    130, the earlier bench.json byte-identical and no lock file left (it died silently, its
    lock left)."""
    before = snapshot(folder)
    for name, sig in [("Ctrl-C", signal.SIGINT), ("SIGTERM", signal.SIGTERM)]:
        with open(tmp / "bench_interrupted.log", "w") as log:
            p = holder(base + ["--steps", "1000000", "--out", folder, "--replace"], log)
            started = wait_for(tmp / "bench_interrupted.log", "steps of each in turn")
            p.send_signal(sig)
            code = p.wait(timeout=120)
        text = (tmp / "bench_interrupted.log").read_text()
        check(f"fem_bench: {name} during --replace stops with a message, exit 130",
              started and code == 130 and "stopped (Ctrl-C or SIGTERM) before the results" in text
              and "is as it was" in text, f"exit {code}: {text}")
        check(f"fem_bench: ... the earlier run byte-identical, the lock released",
              snapshot(folder) == before, sorted(snapshot(folder)))


def sim_cases(sim, tmp):
    base = [sim, "--mesh", MESH, "--chapter", "01"]
    folder = tmp / "sim_out"
    second_run_refused("fem_sim", base + ["--steps", "1000000", "--every", "100000", "--out", folder],
                       base + ["--steps", "2", "--out", folder], folder, tmp)
    p = run(*base, "--steps", "4", "--out", folder)
    check("fem_sim: a run after the first ended writes its series", p.returncode == 0, p.stdout + p.stderr)
    before = snapshot(folder)
    # A run that fails part-way, after some of its frames (a full disk at the third frame, a
    # solve that stops converging at its first step after frame 0): the earlier series, its
    # frames and its .pvd, byte-identical, and nothing of the failed run left.
    for what, args, env, says in [
            ("a failed frame write", ["--steps", "4"], {"FEM_FAIL_WRITES": "cantilever_000002.vtu"},
             "cantilever_000002.vtu': No space left"),
            ("an unconverged solve", ["--steps", "4", "--nu", "0.49999999", "--max-iters", "50"], {},
             "did not converge")]:
        p = run(*base, *args, "--every", "1", "--out", folder, env=env)
        check(f"fem_sim: {what} part-way exits non-zero, with the cause",
              p.returncode == 1 and says in p.stderr and "an earlier series there is as it was" in p.stderr,
              p.stdout + p.stderr)
        check(f"fem_sim: ... and leaves the earlier series byte-identical, no temporary file",
              snapshot(folder) == before, sorted(snapshot(folder)))
    interrupted_case(base, folder, before, tmp)


def interrupted_case(base, folder, before, tmp):
    """Ctrl-C part-way: the run stops after its step, exit 130, says where its frames are; the
    earlier series is byte-identical, the frames so far are a valid series in the staging
    folder, the lock is released (a next run goes ahead and removes them)."""
    with open(tmp / "interrupted.log", "w") as log:
        p = holder(base + ["--steps", "1000000", "--every", "1", "--out", folder], log)
        started = wait_for(folder / ".cantilever.new" / "cantilever_000003.vtu", seconds=120)
        p.send_signal(signal.SIGINT)
        code = p.wait(timeout=120)
    text = (tmp / "interrupted.log").read_text()
    staged = folder / ".cantilever.new" / "cantilever.pvd"
    check("fem_sim: Ctrl-C stops after the step under way, exit 130, naming its frames",
          started and code == 130 and "stopped after step" in text and str(staged) in text, text)
    listed = re.findall(r'file="([^"]+)"', staged.read_text()) if staged.exists() else []
    check("fem_sim: ... its frames so far a whole series in the staging folder",
          len(listed) >= 4 and all((staged.parent / f).exists() for f in listed), listed[:5])
    check("fem_sim: ... the earlier series byte-identical, the lock released",
          {k: v for k, v in snapshot(folder).items() if k != ".cantilever.new"} == before,
          sorted(snapshot(folder)))
    p = run(*base, "--steps", "2", "--out", folder)
    check("fem_sim: ... and the next run goes ahead and removes them",
          p.returncode == 0 and not staged.parent.exists(), p.stdout + p.stderr)


def long_run_case(bench, tmp):
    out = tmp / "long.log"
    with open(out, "w") as log:
        p = holder([bench, "--mesh", MESH, "--chapters", "01", "--no-solvers", "--no-json",
                    "--warmup", "1000000", "--steps", "10"], log)
        try:
            said = wait_for(out, "this run will take about", seconds=300)
        finally:
            p.kill()
            p.wait()
    text = out.read_text()
    check("fem_bench --warmup 1000000: says how long before it goes on, into a file", said, text)
    check("fem_bench --warmup 1000000: the header reaches the file", "fem_bench: scene" in text, text)


def viewer_cases(viewer, tmp):
    """fem_viewer's output files are checked before the work: before the window, so the
    refusal is the same with a display and without one."""
    for option, path, cause in [("--screenshot", "/nonexistent_folder/shot.png", "No such file or directory"),
                                ("--report", tmp, "it is a directory")]:
        p = run(viewer, "--mesh", MESH, "--frames", "2", option, path)
        check(f"fem_viewer {option}: an unwritable path is refused before the work",
              p.returncode == 2 and f"{option}: cannot write '{path}': {cause}" in p.stderr
              and "fem_viewer: cantilever" not in p.stdout, p.stdout + p.stderr)


def plot_case(tmp):
    """The Python writers go through one helper (femtools.files.replacing): a plot
    whose write fails leaves the earlier one."""
    folder = tmp / "plots"
    folder.mkdir()
    (folder / "phases.png").write_bytes(b"the earlier plot")
    plot = [sys.executable, "-m", "femtools", "plots", "bench", ROOT / "tests" / "fixtures" / "bench_fixture.json",
            "--out", folder]
    p = run(*plot, env={"FEM_FAIL_WRITES": "phases.png"})
    check("fem-tools plots bench: a failed plot write exits non-zero, naming the path and the cause",
          p.returncode == 1 and f"cannot write '{folder / 'phases.png'}': No space left" in p.stderr,
          p.stdout + p.stderr)
    check("fem-tools plots bench: ... the earlier plot intact, no temporary left",
          snapshot(folder) == {"phases.png": b"the earlier plot"}, sorted(snapshot(folder)))
    p = run(*plot)
    check("fem-tools plots bench: the plots written whole otherwise",
          p.returncode == 0 and (folder / "phases.png").read_bytes().startswith(b"\x89PNG")
          and not any(n.startswith(".") for n in snapshot(folder)), p.stdout + p.stderr)


def tutorial_sim_case(sim, tmp):
    """./tutorial.sh sim writes its run's folder and no tracked file (the gif in the docs is
    ./tutorial.sh docs's). Run with the preset the tests were built with (build/PRESET/)."""
    build = pathlib.Path(sim).resolve().parent
    if build.parent != ROOT / "build":
        print(f"skip ./tutorial.sh sim: the build {build} is not one of the script's presets")
        return
    gif = ROOT / "docs" / "images" / "cantilever.gif"
    before = gif.read_bytes()
    folder = tmp / "tutorial_sim"
    p = subprocess.run([ROOT / "tutorial.sh", "sim", "--mesh", MESH, "--steps", "4", "--out", folder],
                       capture_output=True, text=True, cwd=ROOT,
                       env={**os.environ, "PRESET": build.name, "FEM_SKIP_PACKAGES": "1"})
    check("./tutorial.sh sim: the frames and the gif in the run's folder",
          p.returncode == 0 and (folder / "cantilever.gif").read_bytes().startswith(b"GIF"),
          p.stdout[-2000:] + p.stderr)
    check("./tutorial.sh sim: docs/images/cantilever.gif untouched", gif.read_bytes() == before)


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--bench", required=True)
    parser.add_argument("--sim", required=True)
    parser.add_argument("--viewer", help="fem_viewer, where it was built")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        bench_cases(args.bench, tmp)
        sim_cases(args.sim, tmp)
        long_run_case(args.bench, tmp)
        plot_case(tmp)
        tutorial_sim_case(args.sim, tmp)
        if args.viewer:
            viewer_cases(args.viewer, tmp)
    print(f"{results['passed']} passed, {results['failed']} failed")
    return 1 if results["failed"] or not results["passed"] else 0


if __name__ == "__main__":
    sys.exit(main())
