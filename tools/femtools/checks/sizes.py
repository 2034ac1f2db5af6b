"""Holds the code to the sizes a reader can take in at once (the developers' guide; issue 33):

  - no .cpp/.hpp in chapters/ over 400 lines;
  - no function (or lambda at file scope) in chapters/, common/ or apps/ over 60 lines, counted
    from the line of its opening brace to the line of its closing one;
  - no struct or class of chapters 09 on with more than 17 data members (the steppers of the
    chapters before, which hold the buffers of a step each named in its comment, are exempt);
  - the same for the Python of tools/femtools/ and meshes/: no file over 400 lines, no function
    (def, at any depth) over 60 lines, from its `def` line to its last line (Python's own parser).

The parser is a brace matcher, not a compiler: comments, string literals and preprocessor
lines are blanked first; a `{` at namespace or class scope opens a namespace, a type (class,
struct, union, enum), a function (its head ends in `)` and qualifiers, or in a constructor's
initializer list) or an initializer (anything else, e.g. `= {...}`, `x_{}`), and everything
inside a function is skipped. A data member is a declaration ending in `;` at class scope that
is not a function, `using`, `typedef`, `friend`, `static` or an access label; `double a, b;`
is two.

    fem-tools check sizes              # exit 1 on any finding
    fem-tools check sizes --root DIR
"""
import ast
import re
import sys

from femtools.args import command_parser, add_root_option


MAX_FILE_LINES = 400
MAX_FUNCTION_LINES = 60
MAX_DATA_MEMBERS = 17
FIRST_CHAPTER_WITH_MEMBER_LIMIT = 9
PYTHON_FOLDERS = ("tools/femtools", "meshes")

TOKEN = re.compile(r'//[^\n]*|/\*.*?\*/|"(?:[^"\\\n]|\\.)*"|\'(?:[^\'\\\n]|\\.)*\'', re.S)
PREPROCESSOR = re.compile(r"^[ \t]*#(?:[^\n]*\\\n)*[^\n]*", re.M)
QUALIFIERS = r"(?:\s|const\b|noexcept\b|override\b|final\b|mutable\b|&|->\s*[\w:<>,\s*&]+)*"
FUNCTION_HEAD = re.compile(r"\)" + QUALIFIERS + r"$")
CONSTRUCTOR_INIT = re.compile(r"\)\s*(?:noexcept\s*)?:(?!:)")
TYPE_HEAD = re.compile(r"\b(class|struct|union|enum)\b")
ACCESS_LABEL = re.compile(r"\b(public|private|protected)\s*:(?!:)")
TEMPLATE_ARGS = re.compile(r"<[^<>;{}]*>")


def blank(text):
    """Comments, literals and preprocessor lines replaced by spaces, the newlines kept."""
    def spaces(m):
        s = m.group(0)
        keep = '""' if s.startswith('"') else "''" if s.startswith("'") else ""
        return keep + re.sub(r"[^\n]", " ", s[len(keep):])
    text = TOKEN.sub(spaces, text)
    return PREPROCESSOR.sub(lambda m: re.sub(r"[^\n]", " ", m.group(0)), text)


def matching(text, open_at):
    """The index of the brace that closes text[open_at]."""
    depth = 0
    for i in range(open_at, len(text)):
        if text[i] == "{":
            depth += 1
        elif text[i] == "}":
            depth -= 1
            if depth == 0:
                return i
    return len(text) - 1


def kind(head):
    """What a `{` after `head` (the text since the last statement) opens."""
    head = " ".join(head.split())
    if re.search(r"\bnamespace\b|\bextern\s*\"\"", head):
        return "namespace"
    if CONSTRUCTOR_INIT.search(head):
        return "function" if head.endswith((")", "}")) else "initializer"
    if FUNCTION_HEAD.search(head) and not head.startswith(("=", "return")):
        return "function"
    without_templates = head
    while TEMPLATE_ARGS.search(without_templates):
        without_templates = TEMPLATE_ARGS.sub(" ", without_templates)
    if TYPE_HEAD.search(without_templates) and "=" not in without_templates:
        return "type"
    return "initializer"


def function_name(head):
    m = re.search(r"([~\w:]+(?:\s*operator\s*[^\s(]+)?)\s*\(", " ".join(head.split()))
    return m.group(1) if m else "a lambda"


def data_members(statement):
    """How many data members a declaration at class scope declares (0 for anything else)."""
    s = " ".join(ACCESS_LABEL.sub(" ", statement).split())
    if not s or re.match(r"(using|typedef|friend|static|template|enum|class|struct|union)\b", s):
        return 0
    while TEMPLATE_ARGS.search(s):
        s = TEMPLATE_ARGS.sub(" ", s)
    if "operator" in s.split("=")[0] or (
            "(" in s and ("=" not in s or s.index("(") < s.index("="))):
        return 0  # a function's declaration (also `= default`, `= delete`, `= 0`)
    depth, count = 0, 1
    for ch in s:
        depth += ch in "([{"
        depth -= ch in ")]}"
        count += ch == "," and depth == 0
    return count


def scan(text, path, lines_of, limit_members):
    """Findings of one blanked source text."""
    problems, stack, head, i = [], ["namespace"], "", 0
    members = []  # per open type: [name, line, count]
    after_type = False  # the `;` after `}` of a type: `} name;` declares members too
    while i < len(text):
        ch = text[i]
        scope = stack[-1]
        if ch == "{":
            what = kind(head)
            if what == "initializer":
                close = matching(text, i)
                head += text[i:close + 1]
                i = close + 1
                continue
            if what == "function":
                close = matching(text, i)
                length = lines_of(close) - lines_of(i) + 1
                if length > MAX_FUNCTION_LINES:
                    problems.append(f"{path}:{lines_of(i)}: {function_name(head)} is {length} "
                                    f"lines long (at most {MAX_FUNCTION_LINES})")
                head, i = "", close + 1
                continue
            if what == "type":
                name = re.findall(r"\b(?:class|struct|union)\s+(?:alignas\s*\([^)]*\)\s*)?(\w+)",
                                  head)
                is_enum = re.search(r"\benum\b", head) and not name
                stack.append("enum" if is_enum else "class")
                if not is_enum:
                    members.append([name[-1] if name else "an unnamed type",
                                    lines_of(i), 0])
            else:
                stack.append("namespace")
            head, i = "", i + 1
            continue
        if ch == "}":
            if scope == "enum":
                stack.pop()
                head, i = "", i + 1
                continue
            if scope == "class":
                name, line, count = members.pop()
                if limit_members and count > MAX_DATA_MEMBERS:
                    problems.append(f"{path}:{line}: {name} has {count} data members "
                                    f"(at most {MAX_DATA_MEMBERS})")
                stack.pop()
                head, i, after_type = "", i + 1, True
                continue
            stack.pop()
            head, i, after_type = "", i + 1, False
            continue
        if ch == ";":
            if scope == "class" and members and (head.strip() or not after_type):
                members[-1][2] += data_members(("T " if after_type else "") + head)
            head, i, after_type = "", i + 1, False
            continue
        if scope in ("namespace", "class"):
            head += ch
        i += 1
    return problems


def check_file(path, root, chapter):
    text = path.read_text()
    rel = path.relative_to(root)
    problems = []
    total = text.count("\n") + (0 if text.endswith("\n") else 1)
    if chapter is not None and total > MAX_FILE_LINES:
        problems.append(f"{rel}: {total} lines (at most {MAX_FILE_LINES} in chapters/)")
    starts = [0] + [m.end() for m in re.finditer("\n", text)]

    def lines_of(index):
        lo, hi = 0, len(starts) - 1
        while lo < hi:
            mid = (lo + hi + 1) // 2
            if starts[mid] <= index:
                lo = mid
            else:
                hi = mid - 1
        return lo + 1
    limit_members = chapter is not None and chapter >= FIRST_CHAPTER_WITH_MEMBER_LIMIT
    return problems + scan(blank(text), rel, lines_of, limit_members)


def check_python(path, root):
    """A Python file's findings: its length, and each function's from its `def` to its last line."""
    text = path.read_text()
    rel = path.relative_to(root)
    problems = []
    if text.count("\n") > MAX_FILE_LINES:
        problems.append(f"{rel}: {text.count(chr(10))} lines (at most {MAX_FILE_LINES})")
    for node in ast.walk(ast.parse(text, str(rel))):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            length = node.end_lineno - node.lineno + 1
            if length > MAX_FUNCTION_LINES:
                problems.append(f"{rel}:{node.lineno}: {node.name} is {length} lines long "
                                f"(at most {MAX_FUNCTION_LINES})")
    return problems


def python_sources(root):
    return [p for folder in PYTHON_FOLDERS for p in sorted((root / folder).rglob("*.py")) if p.is_file()]


def sources(root):
    """(path, chapter number or None) of every C++ source the limits hold for."""
    for folder in ("chapters", "common", "apps"):
        for path in sorted((root / folder).rglob("*")):
            if path.suffix not in (".cpp", ".hpp") or not path.is_file():
                continue
            m = re.match(r"(\d\d)_", path.relative_to(root / folder).parts[0])
            yield path, (int(m.group(1)) if folder == "chapters" and m else None)


def main(argv=None, prog=None):
    parser = command_parser(prog, __doc__)
    add_root_option(parser)
    root = parser.parse_args(argv).root
    found = [(p, check_file(p, root, chapter)) for p, chapter in sources(root)]
    found += [(p, check_python(p, root)) for p in python_sources(root)]
    problems = [problem for _, some in found for problem in some]
    print("\n".join(problems), file=sys.stderr, end="\n" if problems else "")
    if problems:
        print(f"fem-tools check sizes: {len(problems)} finding(s) in {len(found)} files", file=sys.stderr)
        return 1
    print(f"fem-tools check sizes: {len(found)} files: none over {MAX_FILE_LINES} lines in chapters/ or in Python, no "
          f"function over {MAX_FUNCTION_LINES} lines, no type of chapters 09 on with more than "
          f"{MAX_DATA_MEMBERS} data members")
    return 0
