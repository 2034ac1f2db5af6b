#!/usr/bin/env python3
"""fem-tools course compare on two recorded runs: the committed fixture
(tests/fixtures/bench_fixture.json) as the reference, recorded on an AVX2 machine, and a copy of
it recorded on an AVX-512 machine whose chapter 07 solves in half the time. The comparison must
name the instruction set as what differs in the records, mark chapter 07's solve and nothing
else (the other speedups are the same numbers), and draw its plot; the fixture against itself
marks nothing. Prints 'N passed, M failed' last."""
import copy
import json
import pathlib
import re
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parents[2]
FIXTURE = ROOT / "tests" / "fixtures" / "bench_fixture.json"
results = {"passed": 0, "failed": 0}


def check(name, condition, detail=""):
    results["passed" if condition else "failed"] += 1
    print(f"{'ok  ' if condition else 'FAIL'} {name}{'' if condition else ': ' + str(detail)[-3000:]}",
          flush=True)


def with_record(data, isa):
    """The run with a machine record as common/machine_record.cpp writes it."""
    features = ["sse4_2", "avx", "avx2", "fma"] + (["avx512f", "avx512vl"] if isa == "AVX-512" else [])
    data["machine"].update(vendor="AuthenticAMD", family=25, model=1, model_name=data["machine"]["cpu"],
                           isa_build=isa, isa_cpu=isa, features_build=features, features_cpu=features,
                           cores=2, hardware_threads=2, memory_bytes=16 << 30,
                           caches=[{"level": 1, "type": "Data", "bytes": 32 << 10, "shared_by": 1},
                                   {"level": 2, "type": "Unified", "bytes": 512 << 10, "shared_by": 1}])
    return data


def compare(*args):
    return subprocess.run([sys.executable, "-m", "femtools", "course", "compare", *map(str, args)],
                          capture_output=True, text=True)


def main():
    reference = with_record(json.loads(FIXTURE.read_text()), "AVX2")
    run = with_record(copy.deepcopy(reference), "AVX-512")
    shifted = next(c for c in run["chapters"] if c["chapter"] == "07_block_sparse")
    for key in ("median_ms", "min_ms", "q1_ms", "q3_ms", "max_ms"):
        shifted[key]["solve"] /= 2
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        (tmp / "run").mkdir()
        (tmp / "run" / "bench.json").write_text(json.dumps(run))
        (tmp / "reference.json").write_text(json.dumps(reference))
        p = compare(tmp / "run", tmp / "reference.json")
        check("fem-tools course compare runs on the two runs", p.returncode == 0, p.stdout + p.stderr)
        check("the records' difference is the instruction set",
              re.search(r"instruction set \(build\): AVX-512 \| AVX2", p.stdout)
              and re.search(r"instruction set \(CPU\): AVX-512 \| AVX2", p.stdout), p.stdout)
        check("nothing else is named as different but the instruction set",
              "cores / threads" not in p.stdout and "compiler:" not in p.stdout, p.stdout)
        marked = re.findall(r"^differs: (\S+) (\S+):", p.stdout, re.M)
        check("chapter 07's solve, and only it, is marked", marked == [("07_block_sparse", "solve")],
              marked)
        check("the table shows chapter 07's solve speedup doubled and marked",
              re.search(r"^07_block_sparse .*\*", p.stdout, re.M), p.stdout)
        check("the plot of both runs is written beside the run", (tmp / "run" / "compare.png").exists())

        p = compare(FIXTURE, FIXTURE, "--out", tmp)
        check("a run beside itself: no difference in the records, nothing marked",
              p.returncode == 0 and "nothing a ratio depends on" in p.stdout
              and "differs:" not in p.stdout, p.stdout + p.stderr)
        p = compare(tmp / "missing.json")
        check("a missing run is refused with its name", p.returncode != 0 and "missing.json" in p.stderr,
              p.stderr)
    print(f"{results['passed']} passed, {results['failed']} failed")
    return 1 if results["failed"] else 0


if __name__ == "__main__":
    sys.exit(main())
