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
It reads and writes only regular files inside the hand-in (the run's folder, the variants'
folders): a symbolic link anywhere in them, or a name with '..' or '/' in the run's record or on
the command line, is refused before anything is read through it or written. Prints one line per
check and 'N passed, M failed' last; exits 1 on a failure.

A hand-in is code: its tests build the student's CMake and C++ and run them with the rights of
whoever checks (docs/coursework.md, "Checking a hand-in": in a throwaway container or user)."""
import hashlib
import json
import os
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


def refuse(message):
    raise SystemExit(f"fem-tools course handin: {message}")


def plain_name(name, what):
    """A chapter's or a file's name as the hand-in gives it: one name, not a path."""
    if not name or "/" in name or "\\" in name or ".." in name or name.startswith("."):
        refuse(f"{what} '{name}' is not a plain name (no '/', no '..'): refused")
    return name


def links_in(folder):
    """The symbolic links (dangling or not) and the entries that are neither regular files nor
    folders under folder, the folder itself included."""
    if folder.is_symlink():
        return [folder]
    found = []
    for parent, dirs, files in os.walk(folder):
        for name in dirs + files:
            path = pathlib.Path(parent) / name
            if path.is_symlink() or not (path.is_dir() or path.is_file()):
                found.append(path)
    return found


def refuse_links(folder):
    if found := links_in(folder):
        refuse(f"the hand-in holds symbolic links or special files, which the check neither reads "
               f"nor writes through: {', '.join(str(p) for p in found)}; hand in regular files")


def read_bytes(path):
    """A regular file's bytes, never through a link (O_NOFOLLOW: a link made after the scan)."""
    fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW)
    with os.fdopen(fd, "rb") as f:
        return f.read()


def source_hash(folder):
    """As chapters/registry.cmake computes it: SHA-256 of the lines "<file> <SHA-256>\\n" of the
    folder's .cpp and .hpp files, sorted by name."""
    files = sorted(p for p in folder.iterdir() if p.suffix in (".cpp", ".hpp"))
    manifest = "".join(f"{p.name} {hashlib.sha256(read_bytes(p)).hexdigest()}\n" for p in files)
    return hashlib.sha256(manifest.encode()).hexdigest()


def variants_of_run(run, root, wanted):
    rows = {plain_name(row["chapter"], "the run's chapter"): row for row in run["chapters"]}
    for v in wanted:
        plain_name(v, "--variant")
    if wanted:
        missing = [v for v in wanted if v not in rows]
        if missing:
            raise SystemExit(f"fem-tools course handin: the run measured no {', '.join(missing)} "
                             f"(it measured {', '.join(rows)})")
        return [rows[v] for v in wanted]
    variants = [row for cid, row in rows.items() if (root / "chapters" / cid / "variant_of").exists()]
    for row in variants:
        refuse_links(root / "chapters" / row["chapter"])
    return variants


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
              read_bytes(path).decode(errors="replace") == text,
              f"{path} differs from ./tutorial.sh diff {row['chapter']}")
    else:
        # O_EXCL | O_NOFOLLOW: a new regular file, never through a link made after the scan.
        fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW, 0o644)
        with os.fdopen(fd, "w") as f:
            f.write(text)
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
    parser.add_argument("folder", help="the run's folder handed in (bench.json, plots)")
    parser.add_argument("--variant", action="append", default=[], help="the variant to check (default: every variant the run measured)")
    parser.add_argument("--build", type=pathlib.Path, default=ROOT / "build" / "release", help="the build whose tests run")
    parser.add_argument("--no-tests", action="store_true", help="skip the variant's tests")
    add_root_option(parser, hidden=True)
    args = parser.parse_args(argv)
    # An empty name is no folder: as a path it named the working directory (the repository,
    # whose .venv links were then reported as the hand-in's).
    if not args.folder:
        refuse("an empty folder name: give the hand-in's folder (a run's folder)")
    args.folder = pathlib.Path(args.folder)
    json_path = args.folder / "bench.json"
    refuse_links(args.folder)
    if not json_path.is_file():
        refuse(f"no {json_path} (a hand-in is a run's folder)")
    run = json.loads(read_bytes(json_path))
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
