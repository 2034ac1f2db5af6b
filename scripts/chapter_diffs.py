#!/usr/bin/env python3
"""Writes docs/diffs/NN_name.diff: `diff -u` of each chapter's stepper.cpp and stepper.hpp
against the previous chapter's, the lesson of each chapter as a diff. With --check, writes
nothing and exits 1 if a committed diff is stale (the test that keeps them honest).

    .venv/bin/python scripts/chapter_diffs.py            # regenerate
    .venv/bin/python scripts/chapter_diffs.py --check    # compare with the committed ones
"""
import argparse
import difflib
import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent


def chapter_dirs(root):
    """The course's chapters: a student's variant (./tutorial.sh variant, marked by its
    variant_of file) is no lesson, and its diff against the original is the student's own."""
    return sorted(d for d in (root / "chapters").iterdir()
                  if d.is_dir() and d.name[:2].isdigit() and not (d / "variant_of").exists())


def diff(previous, current, root):
    out = []
    for name in ("stepper.hpp", "stepper.cpp"):
        a, b = previous / name, current / name
        out += difflib.unified_diff(
            a.read_text().splitlines(keepends=True), b.read_text().splitlines(keepends=True),
            fromfile=str(a.relative_to(root)), tofile=str(b.relative_to(root)))
    return "".join(out)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--check", action="store_true", help="only check that the diffs are current")
    parser.add_argument("--root", type=pathlib.Path, default=ROOT)
    args = parser.parse_args()
    out_dir = args.root / "docs" / "diffs"
    dirs = chapter_dirs(args.root)
    stale = []
    for previous, current in zip(dirs, dirs[1:]):
        path = out_dir / f"{current.name}.diff"
        text = diff(previous, current, args.root)
        if args.check:
            if not path.exists() or path.read_text() != text:
                stale.append(path)
        else:
            out_dir.mkdir(parents=True, exist_ok=True)
            path.write_text(text)
            print(f"wrote {path.relative_to(args.root)} ({text.count(chr(10))} lines)")
    if stale:
        print("stale chapter diffs (run scripts/chapter_diffs.py):\n  " +
              "\n  ".join(str(p.relative_to(args.root)) for p in stale), file=sys.stderr)
        return 1
    if args.check:
        print(f"{len(dirs) - 1} chapter diffs are current")
    return 0


if __name__ == "__main__":
    sys.exit(main())
