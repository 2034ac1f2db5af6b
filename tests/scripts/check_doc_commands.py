#!/usr/bin/env python3
"""Checks that every ctest command the docs show runs from the repository root: a bare
`ctest -L ch01` there finds no test (the tests live in build/<preset>) and, before the test
presets made "no tests" an error, exited 0. Each must name its build with --preset or
--test-dir (or be written as ./tutorial.sh test)."""
import pathlib
import re
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
COMMAND = re.compile(r"(?<![\w-])ctest(?![\w-])([^`\n]*)")


def doc_files(root):
    yield root / "README.md"
    yield from sorted((root / "docs").glob("*.md"))
    yield from sorted((root / "chapters").glob("*/README.md"))
    yield from sorted((root / "apps").glob("*/README.md"))


def bad_commands(text):
    """The ctest commands of a Markdown text that do not say which build they test."""
    bad = []
    for span in re.findall(r"`([^`\n]+)`", text) + re.findall(r"```[^\n]*\n(.*?)```", text, re.S):
        for match in COMMAND.finditer(span):
            args = match.group(1)
            if args.strip().startswith("#") or not args.strip():
                continue  # "ctest" as a word, or a comment about it
            if "--preset" not in args and "--test-dir" not in args:
                bad.append("ctest" + args)
    return bad


def main():
    assert bad_commands("run `ctest -L ch01` here") == ["ctest -L ch01"]
    assert bad_commands("`ctest --preset release -L ch01` and `./tutorial.sh test -L ch01`") == []
    problems = [f"{f.relative_to(ROOT)}: `{c}` (write `ctest --preset release ...`)"
                for f in doc_files(ROOT) if f.exists() for c in bad_commands(f.read_text())]
    for p in problems:
        print("FAIL", p)
    print(f"{len(problems)} ctest commands in the docs that do not run from the repository root")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
