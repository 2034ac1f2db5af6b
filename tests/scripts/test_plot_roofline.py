#!/usr/bin/env python3
"""fem-tools plots roofline --check on copies of the committed roofline data
(docs/data/lessons/roofline.json): with every measured time at least its bound it passes;
one phase measured below its bound (above 100% of it) is refused, and named; a phase without
its bytes written is refused; the same data marked provisional pass with a warning. The same
checks on the data turned into the format with each phase's waiting (data["bound"]): it passes
and draws; a phase without its waiting, or whose bound is not max(bytes, flops) + waiting, or
whose "held by" is not its largest term, is refused. Prints 'N passed, M failed' last."""
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


def run_check(record, folder, name, *args):
    path = pathlib.Path(folder) / name
    path.write_text(json.dumps(record))
    return subprocess.run([sys.executable, "-m", "femtools", "plots", "roofline", str(path),
                           *(args or ("--check",))], capture_output=True, text=True)


def with_waiting(record):
    """The record as fem_lessons roofline writes it now: each phase's synchronizations (a few
    barriers per phase, priced at the record's own barrier cost), its waiting, its bound
    max(bytes, flops) + waiting and the largest of the three; measured at twice the bound."""
    out = copy.deepcopy(record)
    data = out["data"]
    data["bound"] = "max(memory_s, arithmetic_s) + waiting_s"
    barrier = {roof["threads"]: roof["barrier_s"] for roof in data["roofs"]}
    for r in data["runs"]:
        for k, p in enumerate(r["phases"]):
            p["regions"], p["barriers"] = 1.0, 100.0 * (k + 1)
            p["waiting_s"] = p["barriers"] * barrier[r["threads"]]
            p["bound_s"] = max(p["memory_s"], p["arithmetic_s"]) + p["waiting_s"]
            terms = {"bytes": p["memory_s"], "flops": p["arithmetic_s"]}
            p["held_by"] = "waiting" if p["waiting_s"] > max(terms.values()) else max(terms, key=terms.get)
            p["measured_s"] = 2 * p["bound_s"]
    return out


def check_with_waiting(base, folder):
    new = with_waiting(base)
    out = run_check(new, folder, "new.json")
    check("data with each phase's waiting pass", out.returncode == 0, out.stderr + out.stdout)
    held = [p["held_by"] for r in new["data"]["runs"] for p in r["phases"]]
    check("... and some phase there is held by waiting", "waiting" in held, held)
    png = pathlib.Path(folder) / "new.png"
    out = run_check(new, folder, "new.json", "--out", str(png))
    check("... and draw", out.returncode == 0 and png.exists() and png.stat().st_size > 0, out.stderr)
    for name, change, expect in (
            ("without its waiting", lambda p: p.pop("waiting_s"), "waiting_s"),
            ("whose bound leaves out its waiting", lambda p: p.update(bound_s=p["bound_s"] - p["waiting_s"]),
             "is not max"),
            ("whose 'held by' is not its largest term", lambda p: p.update(held_by="flops"), "held by flops")):
        broken = copy.deepcopy(new)
        phase = next(p for r in broken["data"]["runs"] for p in r["phases"]
                     if p["held_by"] != "flops" and p["waiting_s"] > 0)
        change(phase)
        out = run_check(broken, folder, "broken_new.json")
        check(f"a phase {name} is refused", out.returncode == 1 and expect in out.stderr, out.stderr)


def current(record):
    """The record with the fields fem_lessons roofline writes now, where the committed data
    predate them (issue 56: each level's update and zeroing roofs, each phase's zeroed bytes):
    the placeholders change no bound, since the bounds are the record's own."""
    for roof in record["data"]["roofs"]:
        for level in roof["levels"]:
            level.setdefault("update", 2 * level["read"])
            level.setdefault("zero", level["write"])
    for r in record["data"]["runs"]:
        for p in r["phases"]:
            p.setdefault("bytes_zeroed", 0.0)
    return record


def main():
    base = current(json.loads(DATA.read_text()))
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
        check_with_waiting(base, folder)
    print(f"{results['passed']} passed, {results['failed']} failed")
    return 1 if results["failed"] else 0


if __name__ == "__main__":
    sys.exit(main())
