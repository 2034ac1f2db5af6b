#!/usr/bin/env python3
"""Tests of the results scripts on the committed fixture tests/fixtures/bench_fixture.json
(a real fem_bench run on the test mesh): every plot is written and non-empty, the generated
tables contain the fixture's numbers, and the schema check accepts the fixture and rejects
broken copies. Run from anywhere; prints 'N passed, M failed' last."""
import copy
import json
import pathlib
import shutil
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parents[2]
FIXTURE = ROOT / "tests" / "fixtures" / "bench_fixture.json"
from femtools.docs import markdown
from femtools.plots import bench as plot_results
from femtools.plots import style as plot_style
from femtools.results.common import chapter_dir, footer
from femtools.results.schema import validate_bench, validate_viewer

results = {"passed": 0, "failed": 0}


def check(name, condition, detail=""):
    results["passed" if condition else "failed"] += 1
    print(f"{'ok  ' if condition else 'FAIL'} {name}{'' if condition else ': ' + detail}")


def run(*args):
    return subprocess.run([sys.executable, "-m", "femtools", *map(str, args)], capture_output=True, text=True)


def scaling_fixture(bench):
    runs = []
    for k, nodes in enumerate([500, 1000, 2000, 5000]):
        for c in bench["chapters"][:2]:
            if c["chapter"] != "01_naive" or nodes < 5000:
                runs.append({"chapter": c["chapter"], "mesh": f"beam_{nodes}", "nodes": nodes,
                             "tets": 4 * nodes, "step_ms": c["median_ms"]["step"] * 2 ** k,
                             "solve_ms": c["median_ms"]["solve"] * 2 ** k, "cg_iterations": 10,
                             "allocations_per_step": 0})
    return {"schema_version": 1, "scene": "cantilever", "steps": 5, "warmup_steps": 1, "dt": 0.01,
            "cg_tolerance": 1e-4, "build": bench["build"], "machine": bench["machine"],
            "commit": "fixture", "budget_seconds": 1.0, "runs": runs,
            "skipped": [{"chapter": "01_naive", "mesh": "beam_5000", "reason": "over 1 s"}]}


def viewer_fixture(bench):
    """A results/viewer.json as scripts/viewer_fps.py writes it, with made-up frame rates."""
    def report(run, chapter, fps, step_ms):
        return {"run": run, "chapter": chapter, "mesh": "meshes/test_beam.msh", "nodes": 123,
                "frames": 100, "frames_per_second": fps, "mean_step_ms": step_ms, "width": 640,
                "height": 480, "renderer": "llvmpipe (fixture)", "cpu": bench["machine"]["cpu"],
                "compiler": bench["build"]["compiler"], "flags": bench["build"]["flags"]}
    runs = [report("paused", "07_block_sparse", 31.25, 0.0)]
    runs += [report(c["chapter"], c["chapter"], 5.5 + k, 100.0 / (k + 1)) for k, c in enumerate(bench["chapters"])]
    return {"schema_version": 1, "commit": "fixture", "frames": 100, "runs": runs}


def main():
    bench = json.loads(FIXTURE.read_text())
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        scaling = tmp / "scaling.json"
        scaling.write_text(json.dumps(scaling_fixture(bench)))

        # Plots: every file written and non-empty.
        out = tmp / "plots"
        p = run("plots", "bench", FIXTURE, "--scaling", scaling, "--out", out)
        check("fem-tools plots bench exits 0", p.returncode == 0, p.stderr)
        p = run("plots", "bench", "--threads", FIXTURE, "--out", out)
        check("fem-tools plots bench --threads exits 0", p.returncode == 0, p.stderr)
        for png in ["phases", "phases_stacked", "speedup", "allocations", "solvers", "scaling", "threads"]:
            f = out / f"{png}.png"
            check(f"{png}.png written and non-empty", f.exists() and f.stat().st_size > 10_000,
                  f"{f} missing or small")
        # The figures of chapters 10-12 from the committed data (docs/data/figures/) and
        # chapter 12's sources; a mesh numbered otherwise than the code's record is refused.
        p = run("plots", "figures", "--out", out)
        check("fem-tools plots figures exits 0", p.returncode == 0, p.stderr)
        for png in ["vcycle", "aggregates", "node_orders", "padded_lanes", "soa_batch"]:
            f = out / f"{png}.png"
            check(f"{png}.png written and non-empty", f.exists() and f.stat().st_size > 10_000,
                  f"{f} missing or small")
        data = tmp / "figures"
        data.mkdir()
        record = json.loads((ROOT / "docs" / "data" / "figures" / "hierarchy.json").read_text())
        record["tet_checksum"] += 1
        (data / "hierarchy.json").write_text(json.dumps(record))
        p = run("plots", "figures", "hierarchy", "--data", data, "--out", out)
        check("fem-tools plots figures refuses a mesh not numbered as the code's record",
              p.returncode == 2 and "not numbered here" in p.stderr, p.stderr)
        p = run("plots", "bench", tmp / "missing.json", "--out", out)
        check("fem-tools plots bench on a missing file exits 2 with a message",
              p.returncode == 2 and "no such file" in p.stderr, p.stderr)

        # A variant's run without chapter 01 (--chapters 10,10_mine): each variant row over its
        # original's row at the same thread count, never a blank plot.
        variant_run = copy.deepcopy(bench)
        originals = [c for c in bench["chapters"] if chapter_dir(c["chapter"]) == "09_threads"]
        mine = []
        for c in copy.deepcopy(originals):
            c["chapter"] = c["chapter"].replace("09_threads", "09_mine")
            c["variant_of"] = "09_threads"
            c["median_ms"] = {k: v / 2 for k, v in c["median_ms"].items()}
            mine.append(c)
        variant_run["chapters"] = originals + mine
        pairs, ylabel, _ = plot_results.speedup_references(variant_run)
        check("a variant's run without 01 compares each variant row with its original's",
              [(c["chapter"], r["chapter"]) for c, r in pairs] ==
              [(m["chapter"], o["chapter"]) for m, o in zip(mine, originals)] and "original" in ylabel,
              str([(c["chapter"], r["chapter"]) for c, r in pairs]))
        check("each variant row's speedup over its original is the measured one (x2)",
              all(r["median_ms"]["step"] / c["median_ms"]["step"] == 2.0 for c, r in pairs))
        # The variant's run drawn: the plots' layout checks (no legend over a bar, no tick labels
        # into each other) pass on it, and they do catch a legend laid over the bars.
        (out / "variant").mkdir()
        (out / "variant" / "bench.json").write_text(json.dumps(variant_run))
        p = run("plots", "bench", out / "variant" / "bench.json", "--out", out / "variant")
        check("a variant's run draws readable plots (the layout checks pass)", p.returncode == 0,
              p.stdout + p.stderr)
        import matplotlib.pyplot as plt  # noqa: E402
        fig, ax = plt.subplots()
        ax.bar([0, 1, 2], [3, 3, 3], label="bars")
        ax.legend(loc="center")
        fig.canvas.draw()
        check("the layout check finds a legend that covers bars",
              any("legend" in problem for problem in plot_style.layout_problems(fig)))
        plt.close(fig)
        two = copy.deepcopy(bench)
        two["chapters"] = [c for c in bench["chapters"] if c["chapter"] != "01_naive"][:2]
        pairs, ylabel, _ = plot_results.speedup_references(two)
        check("a run without 01 and without variants compares with its first row",
              len(pairs) == 1 and pairs[0][1] is two["chapters"][0], ylabel)
        # The stacked bars: every row of the run, each as long as its step (the rest fills the
        # gap between the phases' medians and the step's), or as its phases when they exceed it.
        rows = plot_results.stacked_rows(bench)
        check("one stacked bar per row, each reaching its step",
              [r[0] for r in rows] == [c["chapter"] for c in bench["chapters"]] and
              all(min(p) >= 0 and abs(sum(p) - max(step, sum(p[:-1]))) < 1e-9 for _, p, step in rows),
              str(rows[:2]))
        check("rows on two threads are hatched, rows on one are not",
              all((plot_style.style(c)["hatch"] is not None) == (c.get("threads", 1) > 1)
                  for c in bench["chapters"]) and any(c.get("threads", 1) > 1 for c in bench["chapters"]))

        # A run folder holds one run's files: a run without a solve table removes the old one.
        no_solvers = copy.deepcopy(bench)
        del no_solvers["solvers"]
        no_solvers["machine"] = dict(no_solvers["machine"], busy=True, other_cpus=1.5)
        no_solvers["uncommitted"] = ["chapters/09_mine/stepper.cpp", "chapters/09_mine/README.md"]
        (out / "bench.json").write_text(json.dumps(no_solvers))
        p = run("plots", "bench", out / "bench.json", "--out", out)
        check("plots of a run without a solve table remove the folder's old solvers.png",
              p.returncode == 0 and not (out / "solvers.png").exists(), p.stdout + p.stderr)
        check("the footer says the machine was busy and what was measured beyond the commit",
              "BUSY MACHINE" in footer(no_solvers) and "uncommitted chapters/09_mine/" in footer(no_solvers),
              footer(no_solvers))

        # Tables: a copy of the docs with the markers, filled from the fixture.
        root = tmp / "repo"
        for rel in ["README.md", "docs/results.md", "chapters/01_naive/README.md",
                    "chapters/02_noalias/README.md", "chapters/06_custom_pcg/README.md",
                    "chapters/09_threads/README.md"]:
            (root / rel).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy(ROOT / rel, root / rel)
        data = root / "docs" / "data"  # where the JSON behind the committed docs lives
        data.mkdir(parents=True)
        shutil.copy(FIXTURE, data / "bench.json")
        shutil.copy(scaling, data / "scaling.json")
        shutil.copy(FIXTURE, data / "threads.json")
        viewer = viewer_fixture(bench)
        (data / "viewer.json").write_text(json.dumps(viewer))
        p = run("docs", "update", "--root", root, "--check")
        check("fem-tools docs update --check fails on docs made from other data", p.returncode == 1,
              p.stdout + p.stderr)
        p = run("docs", "update", "--root", root)
        check("fem-tools docs update exits 0", p.returncode == 0, p.stderr)
        p = run("docs", "update", "--root", root, "--check")
        check("fem-tools docs update --check passes right after fem-tools docs update", p.returncode == 0,
              p.stdout + p.stderr)
        chapter02 = (root / "chapters" / "02_noalias" / "README.md").read_text()
        check("chapter 02's table has one speedup row (over 01, its previous chapter)",
              chapter02.count("| speedup over `01_naive` |") == 1)
        tampered = (root / "docs" / "results.md").read_text().replace(
            markdown.ms(bench["chapters"][0]["median_ms"]["step"]), "1234.5", 1)
        (root / "docs" / "results.md").write_text(tampered)
        p = run("docs", "update", "--root", root, "--check")
        check("fem-tools docs update --check fails on a hand-edited number", p.returncode == 1 and
              "docs/results.md" in p.stderr, p.stdout + p.stderr)
        run("docs", "update", "--root", root)
        results_md = (root / "docs" / "results.md").read_text()
        naive = next(c for c in bench["chapters"] if c["chapter"] == "01_naive")
        last = bench["chapters"][-1]
        for phase in ["dfdx", "solve", "step"]:
            text = markdown.ms(naive["median_ms"][phase])
            check(f"results.md shows 01's {phase} median {text}", text in results_md)
        speed = markdown.ratio(naive["median_ms"]["step"], last["median_ms"]["step"])
        check(f"results.md shows the step speedup {speed}", speed in results_md)
        check("results.md shows the poster's x218.79", "x218.79" in results_md)
        check("results.md names the machine", bench["machine"]["cpu"] in results_md)
        check("results.md shows the solve table",
              all(f"`{s['name']}`" in results_md for s in bench["solvers"]))
        check("results.md shows the scaling table", "stopped" in results_md)
        readme = (root / "README.md").read_text()
        check("README headline filled", markdown.ms(last["median_ms"]["step"]) in readme)
        check("results.md viewer table filled",
              "| drawing only (`--paused`) | - | 31.2 | - |" in results_md and "llvmpipe (fixture)" in results_md and
              all(f"| `{r['chapter']}` | {format(r['threads'], 'g') if 'threads' in r else '-'} | "
                  f"{r['frames_per_second']:.1f} | {markdown.ms(r['mean_step_ms'])} |"
                  in results_md for r in viewer["runs"][1:]), results_md[results_md.find("viewer-fps"):][:600])
        check("a viewer file without runs is caught", validate_viewer({"runs": []}) != [])
        chapter = (root / "chapters" / "01_naive" / "README.md").read_text()
        check("chapter 01 table filled", markdown.ms(naive["median_ms"]["forces"]) in chapter)
        threaded = [c for c in bench["chapters"] if "@" in c["chapter"]]
        chapter = (root / "chapters" / "09_threads" / "README.md").read_text()
        check("chapter 09 tables filled: NAME@N rows and the thread table",
              all(f"bench-table:{c['chapter']}:begin -->\n| median ms" in chapter for c in threaded) and
              "threads-table:begin -->\n| median ms" in chapter and
              all(markdown.ms(c["median_ms"]["step"]) in chapter for c in threaded),
              chapter[chapter.find("measured effect"):][:800])
        check("README links NAME@N rows to the chapter's directory",
              "[`09_threads@2`](chapters/09_threads/README.md)" in readme)

        # Schema: the fixture passes, broken copies fail.
        check("fixture matches the schema", validate_bench(bench) == [], str(validate_bench(bench)))
        broken = copy.deepcopy(bench)
        del broken["chapters"][0]["median_ms"]["solve"]
        check("a missing phase is caught", validate_bench(broken) != [])
        broken = copy.deepcopy(bench)
        broken["chapters"][-1]["threads"] = 0
        check("a thread count below 1 is caught", validate_bench(broken) != [])
        broken = copy.deepcopy(bench)
        broken["cg_tolerance"] = "tight"
        check("a wrong type is caught", validate_bench(broken) != [])
        broken = copy.deepcopy(bench)
        broken["machine"]["busy"] = "yes"
        check("a busy flag that is not a bool is caught", validate_bench(broken) != [])
        broken = copy.deepcopy(bench)
        broken["uncommitted"] = "chapters/10_mine"
        check("an uncommitted list that is not a list is caught", validate_bench(broken) != [])
        bad = tmp / "broken.json"
        bad.write_text(json.dumps(broken))
        p = run("results", "validate", bad)
        check("fem-tools results validate exits 1 on a broken file", p.returncode == 1, p.stdout + p.stderr)

        # The chapter drift check: a chapter copied forward and not renamed is caught.
        drift = tmp / "drift"
        (drift / "chapters" / "08_copied").mkdir(parents=True)
        (drift / "chapters" / "08_copied" / "stepper.cpp").write_text(
            '// Chapter 07: one linearized backward Euler step\n#include <iostream>\n'
            'void f() { throw 1 ? "07_block_sparse: a table does not match" : ""; }\n')
        p = run("check", "chapter-sources", "--root", drift)
        check("fem-tools check chapter-sources catches a header, a string and an unused <iostream>",
              p.returncode == 1 and "'Chapter 07'" in p.stderr and "names chapter 07" in p.stderr
              and "<iostream>" in p.stderr, p.stderr)
        (drift / "chapters" / "08_copied" / "stepper.cpp").write_text(
            '// Chapter 08: one step, as chapter 07 wrote it\n#include "chapters/07_x/stepper.hpp"\n'
            'void f() { throw "08_copied: a table does not match"; }\n')
        p = run("check", "chapter-sources", "--root", drift)
        check("fem-tools check chapter-sources accepts a chapter that names only itself",
              p.returncode == 0, p.stdout + p.stderr)

        # The size limits: a long function, a long file and a wide struct are caught, and the
        # same code within the limits (a brace in a string, an initializer, a long stepper of
        # an early chapter) is not.
        sizes = tmp / "sizes"
        for folder in ("chapters/09_wide", "chapters/03_early", "common", "apps"):
            (sizes / folder).mkdir(parents=True)
        body = "".join(f"  x += {k};\n" for k in range(59))
        (sizes / "common" / "long.cpp").write_text(
            'int f(int x) {\n  const char* s = "}";\n' + body + "}\n"
            "Foo::Foo() : a_{1}, b_(2) {\n" + body[:-11] + "}\n")
        members = "".join(f"  double m{k} = {{}};\n" for k in range(17))
        (sizes / "chapters" / "09_wide" / "wide.hpp").write_text(
            "struct Wide {\n  using T = int;\n  static constexpr int k = 1;\n  int f() const;\n"
            + members + "  struct Inner {\n    int a, b;\n  } inner, other;\n};\n")
        (sizes / "chapters" / "03_early" / "stepper.hpp").write_text(
            "struct Early {\n" + members + "  int more, still_more;\n};\n" + "\n" * 400)
        p = run("check", "sizes", "--root", sizes)
        check("fem-tools check sizes catches a long function, a long chapter file and a wide struct",
              p.returncode == 1 and "f is 62 lines" in p.stderr and "Foo::Foo" not in p.stderr
              and "Wide has 19 data members" in p.stderr and "Inner" not in p.stderr
              and "stepper.hpp: 420 lines" in p.stderr and "Early has" not in p.stderr, p.stderr)
        (sizes / "common" / "long.cpp").write_text("int f(int x) {\n" + body[:-11] + "}\n")
        (sizes / "chapters" / "09_wide" / "wide.hpp").write_text("struct Wide {\n" + members + "};\n")
        (sizes / "chapters" / "03_early" / "stepper.hpp").write_text("struct Early {};\n")
        p = run("check", "sizes", "--root", sizes)
        check("fem-tools check sizes accepts code within the limits", p.returncode == 0, p.stdout + p.stderr)

    print(f"{results['passed']} passed, {results['failed']} failed")
    return 1 if results["failed"] else 0


if __name__ == "__main__":
    sys.exit(main())
