"""Fails on a Markdown table with a measured number outside the generated markers, in the
README, the chapters' READMEs and docs/*.md (ctest label docs): a measured number is typed
once and goes stale with the next run, so every table of measurements is written between
<!-- NAME:begin --> and <!-- NAME:end --> by fem-tools docs update or fem-tools docs lessons
from the committed JSON.

A cell holds a measured number when, outside its `code` spans, it has
  - a decimal number (0.6, 63.84), except a version of three parts (2.13.10), or
  - a number with a unit of time, size, rate or ratio: 35 s, 4 ms, 12%, 85 MB, 31 GB/s,
    x1.27 or 1.27x.
Counts and identifiers (chapter numbers, 3x3, 16 elements, x86-64) are not measurements.
A table of definitions that needs such a number anyway (a package version, a parameter)
carries `<!-- not measured: REASON -->` on one of the two lines before it.

    fem-tools check doc-numbers      # exit 1 and the tables, if any
"""
import re

from femtools.args import command_parser, add_root_option
from femtools.docs.markers import BEGIN

ALLOW = re.compile(r"<!-- not measured: \S.*-->")
UNIT = r"(?:ms|us|µs|ns|s|%|B|KB|kB|KiB|MB|MiB|GB|GiB|GB/s|MB/s|frames/s)"
MEASURED = re.compile(
    r"(?<![\w.])\d+\.\d+(?![\w.])"                      # a decimal number, not 2.13.10
    r"|(?<![\w.-])\d+(?:\.\d+)?\s?" + UNIT + r"(?![\w/])"  # a number with a unit
    r"|(?<![\w-])x\d+(?:\.\d+)?(?![\w-])"               # x1.27, a ratio
    r"|(?<![\w.-])\d+(?:\.\d+)?x(?![\w-])")             # 1.27x


def doc_files(root):
    yield root / "README.md"
    yield from sorted((root / "docs").glob("*.md"))
    yield from sorted((root / "chapters").glob("*/README.md"))


def measured(cell):
    """The measured numbers of one table cell (code spans left out)."""
    return MEASURED.findall(re.sub(r"`[^`]*`", "", cell))


def tables_outside_markers(text):
    """(line number, first measured number) of each table outside the generated markers and
    code blocks that holds a measured number and no not-measured marker above it."""
    found, lines = [], text.split("\n")
    inside, fenced, start = None, False, None
    for i, line in enumerate(lines + [""]):
        stripped = line.strip()
        if stripped.startswith("```"):
            fenced = not fenced
        if inside is not None:
            inside = None if f"<!-- {inside}:end -->" in line else inside
            continue
        match = BEGIN.search(line)
        if match and f"<!-- {match.group(1)}:end -->" not in line:
            inside = match.group(1)
            continue
        is_row = not fenced and stripped.startswith("|")
        if is_row and start is None:
            start = i
        if not is_row and start is not None:
            rows = lines[start:i]
            allowed = any(ALLOW.search(x) for x in lines[max(0, start - 2):start])
            numbers = [n for row in rows[2:] for cell in row.split("|") for n in measured(cell)]
            if len(rows) > 1 and re.match(r"^\|[\s:|-]+\|$", rows[1].strip()) and numbers \
                    and not allowed:
                found.append((start + 1, numbers[0]))
            start = None
    return found


def self_test():
    assert measured("63.84") == ["63.84"] and measured("35 s against 4 s") == ["35 s", "4 s"]
    assert measured("x1.27, 2.10x and 12%") == ["x1.27", "2.10x", "12%"]
    assert measured("Catch2 2.13.10, 3x3 blocks, x86-64, 16 elements, chapter 09") == []
    assert measured("`-O3 1.5 ms`") == []
    table = "| a | b |\n| --- | ---: |\n| run | {} |\n"
    assert tables_outside_markers(table.format("1.5")) == [(1, "1.5")]
    assert tables_outside_markers(table.format("15")) == []
    assert tables_outside_markers("<!-- t:begin -->\n" + table.format("1.5") + "<!-- t:end -->\n") == []
    assert tables_outside_markers("<!-- not measured: versions -->\n" + table.format("1.5")) == []
    assert tables_outside_markers("```\n" + table.format("1.5") + "```\n") == []


# A lesson, not a lab notebook: the words a page may take (`wc -w`), generated tables included.
WORD_LIMITS = {"README.md": 2500, **{f"chapters/{n}_*/README.md": 3000
                                     for n in ("08", "09", "10", "11", "12", "13", "14")}}


def too_long(root):
    return [f"{path.relative_to(root)}: {words} words, over its limit of {limit}"
            for pattern, limit in WORD_LIMITS.items() for path in sorted(root.glob(pattern))
            if (words := len(path.read_text().split())) > limit and not (path.parent / "variant_of").exists()]


def main(argv=None, prog=None):
    self_test()
    parser = command_parser(prog, __doc__)
    add_root_option(parser)
    root = parser.parse_args(argv).root
    problems = [f"{path.relative_to(root)}:{line}: a table with a measured number ({number}) "
                f"outside the generated markers"
                for path in doc_files(root) if path.exists()
                for line, number in tables_outside_markers(path.read_text())] + too_long(root)
    for p in problems:
        print("FAIL", p)
    print(f"{len(problems)} tables with measured numbers outside the generated markers "
          "(generate them from docs/data/ with fem-tools docs update or fem-tools docs lessons)")
    return 1 if problems else 0
