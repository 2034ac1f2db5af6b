"""Catches the drift of copying a chapter forward: a chapter's source that still names the
chapter it was copied from. For every chapters/NN_name/ directory (so chapters 08 and later
are covered as soon as they exist) and every .cpp/.hpp in it:

  - a line of the header comment (the comment lines that open the file) that starts with
    "Chapter MM" must have MM == NN, and stepper.cpp / stepper.hpp must open with
    "// Chapter NN";
  - a string literal (error messages, warnings) must not name another chapter, neither by
    its directory name ("MM_name") nor as "chapter MM" (except in lesson.cpp, whose tables
    compare the chapter with earlier ones by design: there only a LATER chapter is drift);
  - <iostream> is included only where std::cout, std::cerr or std::clog is used.

    fem-tools check chapter-sources            # exit 1 on any finding
    fem-tools check chapter-sources --root DIR
"""
import re
import sys

from femtools.args import command_parser, add_root_option


CHAPTER_DIR = re.compile(r"^(\d\d)_[A-Za-z0-9_]+$")
STRING = re.compile(r'"(?:[^"\\\n]|\\.)*"')
NAMED_IN_STRING = re.compile(r"\b(\d\d)_[a-z][A-Za-z0-9_]*|\b[Cc]hapter (\d\d)\b")


def header_comment(lines):
    out = []
    for number, line in enumerate(lines, 1):
        if not line.startswith("//"):
            break
        out.append((number, line))
    return out


def check_file(path, nn):
    problems = []
    text = path.read_text()
    lines = text.splitlines()
    header = header_comment(lines)
    if path.name in ("stepper.cpp", "stepper.hpp") and (
            not header or not header[0][1].startswith(f"// Chapter {nn}")):
        problems.append(f"{path}:1: the header comment does not open with 'Chapter {nn}'")
    for number, line in header:
        m = re.match(r"//\s*Chapter (\d\d)\b", line)
        if m and m.group(1) != nn:
            problems.append(f"{path}:{number}: the header comment says 'Chapter {m.group(1)}' "
                            f"in chapter {nn}")
    for number, line in enumerate(lines, 1):
        if re.match(r"\s*#\s*include", line) or line.lstrip().startswith("//"):
            continue  # an include path names the chapter it includes, rightly
        for literal in STRING.findall(line):
            for m in NAMED_IN_STRING.finditer(literal):
                other = m.group(1) or m.group(2)
                if other != nn and (path.name != "lesson.cpp" or other > nn):
                    problems.append(f"{path}:{number}: a string names chapter {other} "
                                    f"in chapter {nn}: {literal}")
    if "#include <iostream>" in text and not re.search(r"std::(cout|cerr|clog)\b", text):
        problems.append(f"{path}: includes <iostream> without using it")
    return problems


def main(argv=None, prog=None):
    parser = command_parser(prog, __doc__)
    add_root_option(parser)
    args = parser.parse_args(argv)
    chapters = sorted(d for d in (args.root / "chapters").iterdir()
                      if d.is_dir() and CHAPTER_DIR.match(d.name))
    if not chapters:
        print(f"fem-tools check chapter-sources: no chapters under {args.root / 'chapters'}",
              file=sys.stderr)
        return 2
    problems, files = [], 0
    for d in chapters:
        nn = CHAPTER_DIR.match(d.name).group(1)
        for path in sorted(list(d.glob("*.cpp")) + list(d.glob("*.hpp"))):
            files += 1
            problems += check_file(path, nn)
    for p in problems:
        print(p, file=sys.stderr)
    if problems:
        print(f"fem-tools check chapter-sources: {len(problems)} finding(s) in {files} files",
              file=sys.stderr)
        return 1
    print(f"fem-tools check chapter-sources: {len(chapters)} chapters, {files} files: no chapter names "
          "another in its header comment or its strings")
    return 0
