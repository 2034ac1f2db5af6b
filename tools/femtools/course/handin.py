"""Checks a student's hand-in in one command (docs/coursework.md, "Checking a hand-in"): a run's
folder (its bench.json and plots) and the variant folder(s) under chapters/ that it measured.

    ./tutorial.sh handin-check handin/06_fused                 # every variant the run measured
    fem-tools course handin handin/06_fused --variant 06_fused --no-tests

For each variant of the run (a chapter whose folder has a variant_of file):
  1. the hash of its sources as they are now equals the one the run recorded when it was
     built (chapters/registry.cmake): the numbers were measured on the code handed in;
  2. its change against its original (./tutorial.sh diff), written to FOLDER/NN_NAME.diff;
     a diff the student handed in there must be the same;
  3. its tests (`ctest -L chNN_NAME`: the checks every chapter passes) pass in the build.
And for the run: the plots regenerate from the JSON alone, pixel for pixel as handed in, and a
run measured on a busy machine is named (its ratios are not to be graded: ask for a rerun).
Prints one line per check and 'N passed, M failed' last; exits 1 on a failure."""
import hashlib
import json
import pathlib
import subprocess
import tempfile

from femtools.args import command_parser, add_root_option
from femtools.docs import diffs
from femtools.paths import ROOT, subcommand


class Checks:
    def __init__(self):
        self.passed = self.failed = 0

    def __call__(self, name, condition, detail=""):
        self.passed += bool(condition)
        self.failed += not condition
        print(f"{'ok  ' if condition else 'FAIL'} {name}" + ("" if condition else f": {detail}"))


def source_hash(folder):
    """As chapters/registry.cmake computes it: SHA-256 of the lines "<file> <SHA-256>\\n" of the
    folder's .cpp and .hpp files, sorted by name."""
    files = sorted(p for p in folder.iterdir() if p.suffix in (".cpp", ".hpp"))
    manifest = "".join(f"{p.name} {hashlib.sha256(p.read_bytes()).hexdigest()}\n" for p in files)
    return hashlib.sha256(manifest.encode()).hexdigest()


def variants_of_run(run, root, wanted):
    rows = {row["chapter"]: row for row in run["chapters"]}
    if wanted:
        missing = [v for v in wanted if v not in rows]
        if missing:
            raise SystemExit(f"fem-tools course handin: the run measured no {', '.join(missing)} "
                             f"(it measured {', '.join(rows)})")
        return [rows[v] for v in wanted]
    return [row for cid, row in rows.items() if (root / "chapters" / cid / "variant_of").exists()]


def check_sources(check, row, root):
    folder = root / "chapters" / row["chapter"]
    if not folder.is_dir():
        check(f"{row['chapter']}: its folder is handed in", False, f"no {folder}")
        return False
    recorded = row.get("source_hash", "")
    check(f"{row['chapter']}: the run measured the sources handed in (hash of its .cpp/.hpp)",
          recorded and recorded == source_hash(folder),
          f"recorded {recorded or 'nothing (a run made before hashes were recorded)'}, "
          f"the folder now {source_hash(folder)}: rerun the bench on the code handed in")
    return True


def check_diff(check, row, root, folder):
    text = diffs.variant_diff(root, row["chapter"])
    path = folder / f"{row['chapter']}.diff"
    if path.exists():
        check(f"{row['chapter']}: the diff handed in is the variant's change",
              path.read_text() == text, f"{path} differs from ./tutorial.sh diff {row['chapter']}")
    else:
        path.write_text(text)
        print(f"     {row['chapter']}: its change against its original written to {path}")
    check(f"{row['chapter']}: the variant changes something", text.strip() != "",
          "its diff against its original is empty")


def check_tests(check, row, build):
    label = "ch" + row["chapter"]
    p = subprocess.run(["ctest", "--test-dir", str(build), "-L", label, "--no-tests=error"],
                       capture_output=True, text=True)
    check(f"{row['chapter']}: its tests pass (ctest -L {label})", p.returncode == 0,
          (p.stdout + p.stderr)[-1500:])


def check_plots(check, folder):
    import matplotlib.image
    import numpy as np
    handed = sorted(folder.glob("*.png"))
    with tempfile.TemporaryDirectory() as tmp:
        argv, env = subcommand("plots", "bench", folder / "bench.json", "--out", tmp)
        p = subprocess.run(argv, env=env, capture_output=True, text=True)
        check("the plots regenerate from the JSON", p.returncode == 0, p.stderr[-1500:])
        for png in handed:
            again = pathlib.Path(tmp) / png.name
            same = again.exists() and np.array_equal(matplotlib.image.imread(png),
                                                     matplotlib.image.imread(again))
            check(f"{png.name} is the plot of the JSON handed in", same,
                  "not made from this bench.json (or another matplotlib drew it)")


def main(argv=None, prog=None):
    parser = command_parser(prog, __doc__)
    parser.add_argument("folder", type=pathlib.Path, help="the run's folder handed in (bench.json, plots)")
    parser.add_argument("--variant", action="append", default=[], help="the variant to check (default: every variant the run measured)")
    parser.add_argument("--build", type=pathlib.Path, default=ROOT / "build" / "release", help="the build whose tests run")
    parser.add_argument("--no-tests", action="store_true", help="skip the variant's tests")
    add_root_option(parser, hidden=True)
    args = parser.parse_args(argv)
    json_path = args.folder / "bench.json"
    if not json_path.is_file():
        raise SystemExit(f"fem-tools course handin: no {json_path} (a hand-in is a run's folder)")
    run = json.loads(json_path.read_text())
    check = Checks()
    rows = variants_of_run(run, args.root, args.variant)
    check("the run measured a variant of a chapter", bool(rows),
          "no chapter of the run is a variant under chapters/ (was the variant's folder handed in?)")
    for row in rows:
        if check_sources(check, row, args.root):
            check_diff(check, row, args.root, args.folder)
            if not args.no_tests:
                check_tests(check, row, args.build)
    check_plots(check, args.folder)
    if run.get("machine", {}).get("busy"):
        print("note: the run was measured on a busy machine (machine.busy in its JSON; the plots' "
              "footnote is red): its times and ratios are not to be graded; ask for a rerun")
    print(f"{check.passed} passed, {check.failed} failed")
    return 1 if check.failed else 0
