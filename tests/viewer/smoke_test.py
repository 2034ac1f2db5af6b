"""Headless smoke test of fem_viewer: without a display it refuses with a message; under
Xvfb (Mesa's software OpenGL) it replays a mouse drag, the dragged node follows the
spring, and the screenshot is a real picture. Exits 77 (skipped) where xvfb-run is absent.

usage: smoke_test.py VIEWER MESH OUT_DIR
"""
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
from matplotlib import image

SKIP = 77
WIDTH, HEIGHT, FRAMES = 800, 600, 60


def check(condition, message):
    if not condition:
        sys.exit(f"FAILED: {message}")
    print(f"ok: {message}")


def without_display(viewer):
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    run = subprocess.run([viewer, "--frames", "1"], env=env, capture_output=True, text=True,
                         timeout=60)
    check(run.returncode == 1, f"without a display it exits with status 1 (got {run.returncode})")
    check("needs a display" in run.stderr, f"and says why: {run.stderr.strip()}")


def scripted_drag(viewer, mesh, out):
    screenshot, report = out / "viewer.png", out / "viewer.json"
    for f in (screenshot, report):
        f.unlink(missing_ok=True)
    command = ["xvfb-run", "-a", "-s", f"-screen 0 {WIDTH}x{HEIGHT}x24", viewer,
               "--mesh", mesh, "--E", "1e6", "--frames", str(FRAMES), "--replay-drag", "auto",
               "--width", str(WIDTH), "--height", str(HEIGHT),
               "--screenshot", str(screenshot), "--report", str(report)]
    print(" ".join(command))
    # Under the asan preset: Mesa's software driver is loaded with dlopen and unloaded at
    # exit, and LeakSanitizer then reports its few hundred bytes from an "<unknown module>"
    # that no suppression can name. The viewer's own code is leak-checked by
    # test_viewer_core; here leaks are not checked (the other ASan checks stay on).
    env = dict(os.environ)
    env["ASAN_OPTIONS"] = env.get("ASAN_OPTIONS", "") + ":detect_leaks=0"
    run = subprocess.run(command, capture_output=True, text=True, timeout=300, env=env)
    print(run.stdout + run.stderr)
    check(run.returncode == 0, f"the scripted run exits with status 0 (got {run.returncode})")

    facts = json.loads(report.read_text())
    check(facts["frames"] == FRAMES and facts["steps"] == FRAMES, "one step per frame")
    check((facts["width"], facts["height"]) == (WIDTH, HEIGHT) and not facts["paused"],
          f"the report records the {WIDTH}x{HEIGHT} framebuffer and a running simulation")
    check(facts["renderer"] not in ("", "unknown") and facts["compiler"] and facts["cpu"],
          f"the report names what the frame rate depends on: {facts['renderer']}, {facts['cpu']}")
    check(facts["grabbed_node"] >= 0, f"the drag grabbed surface node {facts['grabbed_node']}")
    grab, target, end = (np.array(facts[k]) for k in ("node_at_grab", "target", "node_at_end"))
    pull = target - grab
    towards = float(np.dot(end - grab, pull) / np.linalg.norm(pull))
    # Gravity pulls the node down and the drag pulls it up: only the spring moves it
    # this far towards the target.
    check(towards > 0.25 * np.linalg.norm(pull),
          f"the node moved {towards:.3f} m towards the target, "
          f"{np.linalg.norm(pull):.3f} m away at the grab")

    picture = image.imread(screenshot)
    check(picture.shape[:2] == (HEIGHT, WIDTH), f"the screenshot is {WIDTH}x{HEIGHT}")
    colours = len(np.unique((picture[..., :3] * 255).astype(np.uint8).reshape(-1, 3), axis=0))
    check(colours > 100, f"the screenshot is a picture ({colours} colours), not a blank window")


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    viewer, mesh, out = sys.argv[1], sys.argv[2], Path(sys.argv[3])
    out.mkdir(parents=True, exist_ok=True)
    without_display(viewer)
    if shutil.which("xvfb-run") is None:
        print("SKIPPED: xvfb-run not found (./tutorial.sh setup installs the xvfb package)")
        sys.exit(SKIP)
    scripted_drag(viewer, mesh, out)


if __name__ == "__main__":
    main()
