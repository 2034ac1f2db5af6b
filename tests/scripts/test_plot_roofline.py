#!/usr/bin/env python3
"""fem-tools plots roofline --check on copies of the committed roofline data
(docs/data/lessons/roofline.json): with every measured time at least its bound it passes;
one phase measured below its bound (above 100% of it) is refused, and named; a phase without
its bytes written is refused; the same data marked provisional pass with a warning. Prints
'N passed, M failed' last."""
import copy
import json
import pathlib
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parents[2]
DATA = ROOT / "docs" / "data" / "lessons" / "roofline.json"
results = {"passed": 0, "failed": 0}


def check(name, condition, detail=""):
    results["passed" if condition else "failed"] += 1
    print(f"{'ok  ' if condition else 'FAIL'} {name}{'' if condition else ': ' + str(detail)[-2000:]}",
          flush=True)


def run_check(record, folder, name):
    path = pathlib.Path(folder) / name
    path.write_text(json.dumps(record))
    return subprocess.run([sys.executable, "-m", "femtools", "plots", "roofline", str(path), "--check"],
                          capture_output=True, text=True)


def main():
    base = json.loads(DATA.read_text())
    base["data"].pop("provisional", None)
    for r in base["data"]["runs"]:  # every phase at twice its bound
        for p in r["phases"]:
            p["measured_s"] = 2 * p["bound_s"]
    with tempfile.TemporaryDirectory() as folder:
        ok = run_check(base, folder, "ok.json")
        check("every phase under its bound passes", ok.returncode == 0, ok.stderr)
        broken = copy.deepcopy(base)
        run = broken["data"]["runs"][0]
        run["phases"][0]["measured_s"] = 0.5 * run["phases"][0]["bound_s"]
        out = run_check(broken, folder, "broken.json")
        check("a phase above 100% of its bound is refused", out.returncode == 1, out.stdout)
        check("... and named", f"{run['chapter']}@{run['threads']}" in out.stderr and "broken model" in out.stderr,
              out.stderr)
        missing = copy.deepcopy(base)
        del missing["data"]["runs"][0]["phases"][0]["bytes_written"]
        out = run_check(missing, folder, "missing.json")
        check("a phase without its bytes written is refused", out.returncode == 1 and "bytes_written" in out.stderr,
              out.stderr)
        provisional = copy.deepcopy(broken)
        provisional["data"]["provisional"] = "a test"
        out = run_check(provisional, folder, "provisional.json")
        check("provisional data pass with a warning", out.returncode == 0 and "warning" in out.stderr, out.stderr)
    print(f"{results['passed']} passed, {results['failed']} failed")
    return 1 if results["failed"] else 0


if __name__ == "__main__":
    sys.exit(main())
