"""Measures the viewer's frame rate for every chapter (and for drawing alone, paused) on the
poster-sized mesh, headless under Xvfb, and writes results/viewer.json. One fem_viewer run
per chapter, one step per frame; fem-tools docs update turns the file into the table of the
README (the viewer-fps markers).

    fem-tools runs viewer-fps --viewer build/release/fem_viewer

Under Xvfb the OpenGL is Mesa's software renderer (llvmpipe), which draws on the same cores
that step: the frame rates are a floor, and the report names the renderer.
"""
import json
import pathlib
import shutil
import subprocess
import sys
import tempfile

from femtools.args import command_parser
from femtools.paths import ROOT
from femtools.files import write_text

PAUSED = "paused"


def chapter_ids():
    """Every chapter directory, in order (the same names fem_viewer --chapter takes)."""
    return sorted(d.name for d in (ROOT / "chapters").glob("[0-9][0-9]_*")
                  if d.is_dir() and (d / "stepper.hpp").exists())  # a chapter has a stepper


def git_commit():
    """As fem_bench records it (common/build_info.hpp, source_state): a run from uncommitted
    code says so, untracked files under the measured sources (a new variant) included, which
    `git describe --dirty` alone does not see."""
    run = subprocess.run(["git", "-C", str(ROOT), "describe", "--always", "--dirty", "--abbrev=7"],
                         capture_output=True, text=True)
    if run.returncode != 0:
        return "unknown"
    commit = run.stdout.strip()
    status = subprocess.run(["git", "-C", str(ROOT), "status", "--porcelain", "--untracked-files=all",
                             "--", "chapters", "common", "apps", "CMakeLists.txt", "CMakePresets.json"],
                            capture_output=True, text=True)
    if status.returncode == 0 and status.stdout.strip() and not commit.endswith("-dirty"):
        commit += "-dirty"
    return commit


def run_one(viewer, mesh, chapter, frames, size, report):
    cmd = ["xvfb-run", "-a", "-s", f"-screen 0 {size[0]}x{size[1]}x24", viewer, "--mesh", mesh,
           "--frames", str(frames), "--width", str(size[0]), "--height", str(size[1]),
           "--report", str(report)]
    cmd += ["--paused"] if chapter == PAUSED else ["--chapter", chapter]
    try:
        run = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    except subprocess.TimeoutExpired:
        raise SystemExit(f"fem-tools runs viewer-fps: {' '.join(cmd)} did not finish in 10 minutes") from None
    if run.returncode != 0:
        raise SystemExit(f"fem-tools runs viewer-fps: {' '.join(cmd)} failed ({run.returncode}):\n{run.stderr}")
    return json.loads(report.read_text())


def main(argv=None, prog=None):
    parser = command_parser(prog, __doc__)
    parser.add_argument("--viewer", default=str(ROOT / "build" / "release" / "fem_viewer"))
    parser.add_argument("--mesh", default=str(ROOT / "meshes" / "plate_poster.msh"))
    parser.add_argument("--frames", type=int, default=100, help="frames per run")
    parser.add_argument("--chapters", default="all", help="comma-separated, or all")
    parser.add_argument("--size", default="1280x800", help="window size WIDTHxHEIGHT")
    parser.add_argument("--out", default=str(ROOT / "results" / "viewer.json"))
    args = parser.parse_args(argv)
    if args.frames < 10:
        parser.error("--frames must be at least 10 (the first frames set up the GL state)")
    parts = args.size.split("x")
    size = tuple(int(v) for v in parts) if len(parts) == 2 and all(v.isdigit() for v in parts) else ()
    if not size or min(size) < 64:
        parser.error(f"--size must be WIDTHxHEIGHT, at least 64x64 (got '{args.size}')")
    if not pathlib.Path(args.viewer).exists():
        sys.exit(f"fem-tools runs viewer-fps: {args.viewer} does not exist (was fem_viewer built? see the CMake warning)")
    if shutil.which("xvfb-run") is None:
        sys.exit("fem-tools runs viewer-fps: xvfb-run is missing (Debian package xvfb; ./tutorial.sh setup installs it)")

    chapters = chapter_ids() if args.chapters == "all" else args.chapters.split(",")
    runs = []
    with tempfile.TemporaryDirectory() as tmp:
        for k, chapter in enumerate([PAUSED] + chapters):
            print(f"  [{k + 1}/{len(chapters) + 1}] {chapter}: {args.frames} frames ...", end="", flush=True)
            facts = run_one(args.viewer, args.mesh, chapter, args.frames, size, pathlib.Path(tmp) / "r.json")
            facts["run"] = chapter
            runs.append(facts)
            print(f" {facts['frames_per_second']:.1f} frames/s, mean step {facts['mean_step_ms']:.1f} ms",
                  flush=True)
    out = pathlib.Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    write_text(out, json.dumps({"schema_version": 1, "commit": git_commit(), "frames": args.frames,
                               "runs": runs}, indent=2) + "\n")
    print(f"wrote {out}")
