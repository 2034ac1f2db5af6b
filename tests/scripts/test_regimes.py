#!/usr/bin/env python3
"""Test of the regime sweep's driver: a short run of `fem-tools runs regimes` on the test mesh with
two values of E writes a regimes.json that passes the schema check, with every chapter of the
registry at every point and chapter 01's CG iterations rising with stiffness; the plot and the
generated docs sections come from it; the schema check rejects broken copies.

    test_regimes.py path/to/fem_bench [work directory]

Prints 'N passed, M failed' last; exits 1 if any check failed."""
import copy
import json
import pathlib
import shutil
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parents[2]
from femtools.docs import regime_tables
from femtools.docs import update as update_docs
from femtools.results import poster
from femtools.results import regimes as regimes_common

results = {"passed": 0, "failed": 0}
SOFT, STIFF = 1e4, 1e6


def check(name, condition, detail=""):
    results["passed" if condition else "failed"] += 1
    print(f"{'ok  ' if condition else 'FAIL'} {name}{'' if condition else ': ' + detail}", flush=True)


def registry_chapters(bench, tmp):
    """The chapters fem_bench runs with --chapters all: one step each on the test mesh."""
    out = tmp / "registry.json"
    subprocess.run([bench, "--mesh", str(ROOT / "meshes" / "test_beam.msh"), "--steps", "1", "--warmup", "1",
                    "--no-solvers", "--json", str(out), "--replace"], check=True, capture_output=True)
    return [c["chapter"] for c in json.loads(out.read_text())["chapters"]]


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    bench = sys.argv[1]
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(sys.argv[2]) if len(sys.argv) > 2 else pathlib.Path(tmp)
        tmp.mkdir(parents=True, exist_ok=True)
        out = tmp / "regimes.json"
        p = subprocess.run([sys.executable, "-m", "femtools", "runs", "regimes", "--bench", bench,
                            "--bodies", str(ROOT / "meshes" / "test_beam.msh"), "--E", f"{STIFF:g},{SOFT:g}",
                            "--steps", "2", "--warmup", "1", "--out", str(out)],
                           capture_output=True, text=True)
        check("fem-tools runs regimes exits 0", p.returncode == 0, p.stderr)
        check("fem-tools runs regimes reports progress per point", "[2/2] test_beam.msh" in p.stdout, p.stdout[-500:])
        if p.returncode != 0:
            return
        data = json.loads(out.read_text())
        problems = regimes_common.validate_regimes(data)
        check("the JSON passes the schema check", not problems, "; ".join(problems))
        v = subprocess.run([sys.executable, "-m", "femtools", "results", "validate", "--regimes", str(out)],
                           capture_output=True, text=True)
        check("fem-tools results validate --regimes accepts it", v.returncode == 0, v.stderr)
        check("two points, sorted by E", [pt["E"] for pt in data["points"]] == [SOFT, STIFF],
              str([pt["E"] for pt in data["points"]]))
        expected = registry_chapters(bench, tmp)
        for pt in data["points"]:
            got = [c["chapter"] for c in pt["chapters"]]
            check(f"every chapter of the registry at E = {pt['E']:g}", got == expected, f"{got} vs {expected}")
            check(f"the solve table at E = {pt['E']:g}", len(pt.get("solvers", [])) > 0)
        soft, stiff = data["points"]
        check("chapter 01's CG iterations rise with stiffness",
              regimes_common.iterations(stiff) > regimes_common.iterations(soft),
              f"{regimes_common.iterations(soft)} at E = {SOFT:g}, {regimes_common.iterations(stiff)} at {STIFF:g}")
        check("Eigen solve()'s iterations rise with stiffness",
              stiff["solvers"][0]["iterations"] > soft["solvers"][0]["iterations"])
        png = tmp / "regimes.png"
        check("regimes.png written and non-empty", png.exists() and png.stat().st_size > 20_000)

        # The generated sections: one row per poster number, from this JSON.
        statements = regimes_common.poster_statements(data)
        for _, label, target in poster.NUMBERS:
            check(f"the statements name the poster's x{target:g}", f"x{target:g}" in statements)
        table = regime_tables.regimes_points_table(data)
        check("the points table has a row per point", table.count("`test_beam`") == 2, table)
        solvers = regime_tables.regimes_solvers_table(data)
        check("the solve table shows the softest and the stiffest point",
              f"E = {SOFT:g}" in solvers and f"E = {STIFF:g}" in solvers, solvers)
        repo = tmp / "repo"
        shutil.rmtree(repo, ignore_errors=True)  # a previous run's copy, in a kept work directory
        (repo / "docs").mkdir(parents=True)
        for f in ("README.md", "docs/results.md"):
            (repo / f).write_text((ROOT / f).read_text())
        update_docs.update_regimes(repo, out, repo / "docs" / "images")
        check("docs/results.md gets the statements", statements in (repo / "docs" / "results.md").read_text())
        check("README.md gets the statements", statements in (repo / "README.md").read_text())
        check("the JSON behind the docs is kept in docs/data/",
              (repo / "docs" / "data" / "regimes.json").read_text() == out.read_text())
        check("regimes.png copied to docs/images/", (repo / "docs" / "images" / "regimes.png").exists())

        # The schema check rejects broken copies.
        for name, breaks in [
            ("a point without chapter 01", lambda d: d["points"][0]["chapters"].pop(0)),
            ("a point missing a chapter", lambda d: d["points"][1]["chapters"].pop()),
            ("a negative E", lambda d: d["points"][0].__setitem__("E", -1.0)),
            ("a body without all E values", lambda d: d["points"].pop()),
            ("a phase missing", lambda d: d["points"][0]["chapters"][0]["median_ms"].pop("solve")),
            ("no knob", lambda d: d.pop("knob")),
        ]:
            broken = copy.deepcopy(data)
            breaks(broken)
            check(f"the schema check rejects {name}", bool(regimes_common.validate_regimes(broken)))
        bad = subprocess.run([sys.executable, "-m", "femtools", "runs", "regimes", "--bench", bench, "--E", "0"],
                             capture_output=True, text=True)
        check("fem-tools runs regimes refuses E = 0 with a message", bad.returncode == 2 and "positive" in bad.stderr,
              bad.stderr)


if __name__ == "__main__":
    main()
    print(f"{results['passed']} passed, {results['failed']} failed")
    sys.exit(1 if results["failed"] else 0)
