"""The lessons' tables as committed data: every docs/data/lessons/NAME.json (written by
`fem_lessons NAME --json`, or by fem-tools runs pyamg --json) holds a table and the
README and markers it belongs between. This script writes each table there; with --check it
writes nothing and fails when a README's table is not its JSON's (ctest label docs), so that
no number of a lesson is typed by hand or left behind by a rerun.

    fem-tools docs lessons            # write the tables into the READMEs
    fem-tools docs lessons --check    # are the READMEs those of the JSON?
"""
import json
import sys

from femtools.args import command_parser, add_root_option
from femtools.docs import kernels_alone, layouts, provenance
from femtools.docs.markers import names_in, replace_between
FIELDS = ("lesson", "readme", "marker", "command", "table")
# Sections of a lesson's page written from its record besides its table (where the page has them).
def roofline_kernels_alone(record, where):
    return kernels_alone.section(record.get("data"), where)


DATA_SECTIONS = {"roofline": {kernels_alone.MARKER: roofline_kernels_alone},
                 "every-lane": {layouts.MARKER: layouts.section}}


def load(path):
    data = json.loads(path.read_text())
    missing = [f for f in FIELDS if f not in data]
    if missing:
        raise ValueError(f"{path}: no {', '.join(missing)}")
    return data


def with_data_sections(text, data, where=None):
    """text (None: a page without the table's markers) with the lesson's data sections written
    where it has their markers (where: the machine, compiler and commit they were recorded on)."""
    for marker, render in DATA_SECTIONS.get(data["lesson"], {}).items():
        if text is not None:
            text = replace_between(text, marker, render(data, where)) or text
    return text


def with_provenance(root, path, data):
    """The lesson's tables, each one's own caption naming the machine, the compiler and the
    commit it was recorded on (a table without a machine record, counts from Python, as it is):
    the commit alone where a caption already names the machine and the compiler."""
    machine = data.get("machine")
    if not isinstance(machine, dict):
        return data["table"], None
    compiler, commit = provenance.lesson_build(root, path, data)
    where = provenance.describe(machine, compiler, commit, data.get("uncommitted"))
    names = (machine.get("cpu") or machine.get("model_name") or "", compiler or "",
             provenance.short_commit(commit, data.get("uncommitted")))
    return captioned(data["table"], names, where), where


def blocks(text):
    """text as its runs of lines: [is a table, lines]."""
    runs = []
    for line in text.split("\n"):
        row = line.startswith("|")
        if runs and runs[-1][0] == row:
            runs[-1][1].append(line)
        else:
            runs.append([row, [line]])
    return runs


def with_names(caption, names, where):
    """A table's caption (its lines up to the next table) that names its machine, compiler and
    commit (names): as it is where it does, else with the missing ones added to its last line."""
    cpu, compiler, commit = names
    text = "\n".join(caption)
    if all(n and n in text for n in names):
        return caption
    added = f"Recorded at commit {commit}." if cpu and cpu in text and compiler and compiler in text \
        else f"Recorded on {where}."
    last = max((i for i, line in enumerate(caption) if line.strip()), default=None)
    if last is None:  # a table directly followed by the next: a caption of its own
        return ["", added, ""]
    line = caption[last].rstrip()
    caption = list(caption)
    caption[last] = line + (" " if line.endswith(".") else ". ") + added
    return caption


def captioned(table, names, where):
    """Every table of a lesson's text with a caption of its own naming where it was recorded:
    a block of several tables names it under each, not only under the last."""
    runs = blocks(table.rstrip("\n"))
    if runs and runs[-1][0]:
        runs.append([False, [""]])
    out = []
    for k, (row, lines) in enumerate(runs):
        if not row and k > 0:
            lines = with_names(lines, names, where)
        out.extend(lines)
    return "\n".join(out).rstrip("\n") + "\n"


def chapter_kernels_alone(root, data, where=None):
    """The chapters' READMEs with a section `roofline-kernels-alone:NN,MM` (a chapter's kernels
    alone beside those of the chapter it replaces), written from the roofline's data: path ->
    new text, for those whose text it changes."""
    changed = {}
    for readme in sorted((root / "chapters").glob("*/README.md")):
        text = new = readme.read_text()
        for name in names_in(text):
            if not name.startswith(kernels_alone.MARKER + ":"):
                continue
            ids = name.split(":", 1)[1].split(",")
            runs = (data or {}).get("kernels_alone") or []
            mine = {"kernels_alone": [r for r in runs if r["chapter"][:2] in ids]}
            new = replace_between(new, name, kernels_alone.section(mine, where))
        if new != text:
            changed[readme] = new
    return changed


def main(argv=None, prog=None):
    parser = command_parser(prog, __doc__)
    parser.add_argument("--check", action="store_true", help="only check the READMEs")
    add_root_option(parser)
    args = parser.parse_args(argv)
    paths = sorted((args.root / "docs" / "data" / "lessons").glob("*.json"))
    if not paths:
        print("fem-tools docs lessons: no docs/data/lessons/*.json", file=sys.stderr)
        return 1
    problems = []
    for path in paths:
        data = load(path)
        readme = args.root / data["readme"]
        text = readme.read_text()
        table, where = with_provenance(args.root, path, data)
        new = with_data_sections(replace_between(text, data["marker"], table), data, where)
        if new is None:
            problems.append(f"{data['readme']} has no {data['marker']} markers (from {path.name})")
        elif new != text:
            if args.check:
                problems.append(f"{data['readme']}: the {data['marker']} table is not {path.name}'s "
                                f"(run fem-tools docs lessons)")
            else:
                readme.write_text(new)
                print(f"wrote the {data['marker']} table of {data['readme']} from {path.name}")
        if data["lesson"] == "roofline":
            for page, new_text in chapter_kernels_alone(args.root, data.get("data"), where).items():
                name = page.relative_to(args.root)
                if args.check:
                    problems.append(f"{name}: its kernels-alone table is not {path.name}'s "
                                    "(run fem-tools docs lessons)")
                else:
                    page.write_text(new_text)
                    print(f"wrote the kernels-alone table of {name} from {path.name}")
    if problems:
        print("\n".join(problems), file=sys.stderr)
        return 1
    if args.check:
        print(f"{len(paths)} lesson tables are those of docs/data/lessons/")
    return 0
