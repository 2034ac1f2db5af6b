"""Writes docs/diffs/NN_name.diff: the lesson of each chapter as a diff against the chapter it
builds on (femtools.course.tree.parent_of: the recipe's BuildsOn from chapter 09 on, else the
chapter before). Every source file of the chapter's folder (.hpp, .cpp), in reading order
(source_files), is diffed against the file of the same name in the parent only where the
chapter copied it (copied_files): the parent has the name, and no file of the chapter includes
the parent's file of that name (nor its header), which would make it a new file that shares a
name, such as a parts.hpp beside the parent's. A recipe (chapter 09 on) copies only its
stepper.hpp, diffed against its parent's; its parts are its own files. Every other file shows as added,
and so do the lesson measurements (lesson.hpp, lesson.cpp), which never copy forward. Before
diffing, the parent's code gets the chapter's names (namespace chNN, stepper class, chapter id,
the paths of the files it copied), so that no hunk is a rename; its words stay its own
("Chapter 12" stays "Chapter 12"). It also writes the table of each chapter's files and what
it includes from earlier chapters into chapters/README.md (between its chapter-files markers;
the table of which part runs each phase, between its phase-owners markers, is the program's:
`fem_lessons phase-owners --write chapters/README.md`, from the steppers' recipes). With
--check, writes nothing and exits 1 if a committed diff or the files table is stale or any hunk
only changes names.

    fem-tools docs diffs                    # regenerate
    fem-tools docs diffs --check            # compare with the committed ones
    fem-tools docs diffs --variant 10_mine  # a variant against its original
"""
import difflib
import pathlib
import re
import sys

from femtools.args import command_parser, add_root_option
from femtools.course import variant as make_variant
from femtools.course.tree import BUILDS_ON, course_chapters, parent_of
from femtools.docs.markers import replace_between

STEPPER_CLASS = re.compile(r"class\s+(\w+)\s+(?:final\s+)?:\s*public\s+[\w:]*Stepper\b"
                           r"|using\s+(\w+)\s*=\s*[\w:]*StepOf<")
ALWAYS_ADDED = ("lesson.hpp", "lesson.cpp")


def chapter_dirs(root):
    """The course's chapters: a student's variant is no lesson, and its diff against the
    original is the student's own (variant_diff)."""
    return course_chapters(root)


def names(chapter):
    """What is renamed from chapter to chapter: namespace, stepper class, recipe, id, number."""
    text = (chapter / "stepper.hpp").read_text()
    match = STEPPER_CLASS.search(text)
    namespace = re.search(r"namespace fem::(\w+) \{", text)
    recipe = re.search(r"StepOf<(\w+)>", text)
    return {"id": chapter.name, "number": chapter.name[:2],
            "namespace": namespace.group(1) if namespace else "",
            "class": (match.group(1) or match.group(2)) if match else "",
            "recipe": recipe.group(1) if recipe else ""}


def renamed(text, old, new, files=(), recipe=False):
    """text of chapter `old` with the code names of chapter `new` (namespace, stepper, recipe), which copied `files` from
    it; the words stay the old text's ("Chapter NN" is not renamed). In a recipe (`recipe`) a
    qualified name such as ch10::Extrapolation names chapter 10's part in either chapter: only
    the chapter's own namespace (fem::ch10) is renamed."""
    # Its stepper.hpp (the registry's file) and the files the new chapter copied, under the new
    # chapter's path.
    own = "|".join(re.escape(f) for f in sorted({"stepper.hpp", *files}))
    text = re.sub(rf"chapters/{old['id']}/({own})\b", rf"chapters/{new['id']}/\1", text)
    text = re.sub(rf"(?<!chapters/)\b{old['id']}\b", new["id"], text)
    if old["namespace"] and recipe:
        text = re.sub(rf"\bfem::{old['namespace']}\b", f"fem::{new['namespace']}", text)
    elif old["namespace"]:
        text = re.sub(rf"\b{old['namespace']}\b", new["namespace"], text)
    for name in ("class", "recipe"):
        if old[name] and new[name]:
            text = re.sub(rf"\b{old[name]}\b", new[name], text)
    return text


def source_files(chapter):
    """The chapter's sources in reading order: the headers (the interfaces) before the sources,
    and within each the stepper first, then the building blocks in the order in which the
    chapter's README first names them (a file it never names after those, alphabetically),
    the lesson's measurements last."""
    readme_path = chapter / "README.md"
    readme = readme_path.read_text() if readme_path.exists() else ""

    def key(path):
        stem = path.stem
        named = re.search(rf"\b{re.escape(stem)}\.(?:hpp|cpp)\b", readme)
        role = 0 if stem == "stepper" else 2 if stem == "lesson" else 1
        return (path.suffix != ".hpp", role, named.start() if named else len(readme), path.name)
    return sorted((p for p in chapter.iterdir() if p.suffix in (".hpp", ".cpp")), key=key)


def includes_of(chapter):
    """The (folder, file) pairs the chapter's sources include from chapters/."""
    return {m.groups() for p in chapter.iterdir() if p.suffix in (".hpp", ".cpp")
            for m in INCLUDE.finditer(p.read_text())}


def copied_files(parent, chapter):
    """The chapter's files that are copies of its parent's: the parent has a file of the name,
    and the chapter includes neither it nor its header (a chapter that includes the parent's
    parts.hpp and has a parts.hpp of its own wrote a new one). A recipe (a chapter whose
    stepper.hpp names BuildsOn) copies its stepper.hpp only: it includes its parent's to name it,
    and its diff is the lesson; every part it adds is a file of its own (chapter 10's work.hpp
    counts its V-cycle, chapter 09's its threads: the same name, no line in common to diff)."""
    if BUILDS_ON.search((chapter / "stepper.hpp").read_text()):
        return {"stepper.hpp"} if (parent / "stepper.hpp").exists() else set()
    included = {name for folder, name in includes_of(chapter) if folder == parent.name}
    return {path.name for path in chapter.iterdir()
            if path.suffix in (".hpp", ".cpp") and path.name not in ALWAYS_ADDED
            and (parent / path.name).exists()
            and path.name not in included and f"{path.stem}.hpp" not in included}


def file_diff(parent, current, name, root, copied):
    b = current / name
    new_lines = b.read_text().splitlines(keepends=True)
    if name not in copied:
        return list(difflib.unified_diff([], new_lines, fromfile="/dev/null",
                                         tofile=str(b.relative_to(root))))
    a = parent / name
    recipe = bool(BUILDS_ON.search((current / "stepper.hpp").read_text()))
    old_text = renamed(a.read_text(), names(parent), names(current), copied, recipe)
    return list(difflib.unified_diff(old_text.splitlines(keepends=True), new_lines,
                                     fromfile=str(a.relative_to(root)),
                                     tofile=str(b.relative_to(root))))


def diff(parent, current, root):
    """The chapter `current` against the chapter it builds on, `parent`."""
    copied = copied_files(parent, current)
    out = []
    for path in source_files(current):
        out += file_diff(parent, current, path.name, root, copied)
    return "".join(out)


# The code's names of a chapter (not "Chapter NN", a word of the text, which the diff keeps).
GENERIC = [(re.compile(r"\bch\d\d\w*"), "chNN"), (re.compile(r"\b\d\d_[a-z]\w*"), "NN_name"),
           (re.compile(r"\b\w+Stepper\b"), "Stepper")]


def rename_only_hunks(text):
    """The hunks whose removed and added lines are the same once every chapter name is
    replaced by a placeholder: a change of names only."""
    def generic(line):
        for pattern, placeholder in GENERIC:
            line = pattern.sub(placeholder, line)
        return line
    found, removed, added, header = [], [], [], None

    def close():
        if header and (removed or added) and [generic(l) for l in removed] == [generic(l) for l in added]:
            found.append(header.strip())
    for line in text.splitlines():
        if line.startswith("@@"):
            close()
            header, removed, added = line, [], []
        elif line.startswith("-") and not line.startswith("---"):
            removed.append(line[1:])
        elif line.startswith("+") and not line.startswith("+++"):
            added.append(line[1:])
    close()
    return found


def variant_diff(root, variant):
    """The variant's change: its files against the original's as `fem-tools course variant` copied them
    (the same renames of namespace, include paths and README heading), so that a one-line
    change is one hunk."""
    current = find_variant(root, variant)
    variant = current.name
    original = root / "chapters" / (current / "variant_of").read_text().strip()
    number = original.name[:2]
    out = []
    for path in sorted(p for p in current.iterdir() if p.is_file() and p.name != "variant_of"):
        a = original / path.name
        old = a.read_text() if a.exists() else ""
        if path.name == "README.md" and old:
            old = make_variant.readme_heading(old, original.name, variant)
        # Both sides in the original's names: the context reads as the original's code.
        new = make_variant.unrewrite(path.read_text(), original.name, variant, number)
        out += difflib.unified_diff(old.splitlines(keepends=True), new.splitlines(keepends=True),
                                    fromfile=str(a.relative_to(root)), tofile=str(path.relative_to(root)))
    return "".join(out)


def find_variant(root, name):
    """A variant by its folder (10_mine) or by its name alone (mine), as chapters/README.md
    says a variant answers to its name; refused when no variant or several have it."""
    chapters = root / "chapters"
    found = [chapters / name] if (chapters / name / "variant_of").exists() else sorted(
        d for d in chapters.glob(f"[0-9][0-9]_{name}") if (d / "variant_of").exists())
    if len(found) != 1:
        known = ", ".join(sorted(d.parent.name for d in chapters.glob("*/variant_of"))) or "none"
        what = "no variant" if not found else "several variants"
        raise SystemExit(f"fem-tools docs diffs: {what} named '{name}' (variants: {known})")
    return found[0]


INCLUDE = re.compile(r'#include "chapters/(\d\d_\w+)/([\w.]+)"')
FILES_MARKER = "chapter-files"


def files_table(dirs):
    """Per chapter, its source files and the files of earlier chapters it includes (what a
    student opens in the earlier chapter's folder), from the sources themselves."""
    rows = ["| chapter | its files (besides `README.md`) | includes from earlier chapters |",
            "| --- | --- | --- |"]
    for chapter in dirs:
        own = ", ".join(f"`{p.name}`" for p in source_files(chapter))
        included = sorted({m.groups() for p in source_files(chapter)
                           for m in INCLUDE.finditer(p.read_text()) if m.group(1) != chapter.name})
        earlier = ", ".join(f"{c[:2]}'s `{f}`" for c, f in included)
        rows.append(f"| {chapter.name[:2]} | {own} | {earlier} |")
    return "\n".join(rows) + "\n"


def with_files_table(text, table):
    """chapters/README.md's text with the table between its markers (None: no markers)."""
    return replace_between(text, FILES_MARKER, table)


def main(argv=None, prog=None):
    parser = command_parser(prog, __doc__)
    parser.add_argument("--check", action="store_true", help="only check that the diffs are current")
    parser.add_argument("--variant", help="print a variant's change against its original instead")
    add_root_option(parser)
    args = parser.parse_args(argv)
    if args.variant:
        sys.stdout.write(variant_diff(args.root, args.variant))
        return 0
    out_dir = args.root / "docs" / "diffs"
    dirs = chapter_dirs(args.root)
    stale, renames = [], []
    for current in dirs[1:]:
        path = out_dir / f"{current.name}.diff"
        text = diff(parent_of(current), current, args.root)
        renames += [f"{path.name}: {h}" for h in rename_only_hunks(text)]
        if args.check:
            if not path.exists() or path.read_text() != text:
                stale.append(path)
        else:
            out_dir.mkdir(parents=True, exist_ok=True)
            path.write_text(text)
            print(f"wrote {path.relative_to(args.root)} ({text.count(chr(10))} lines)")
    readme = args.root / "chapters" / "README.md"
    text = readme.read_text() if readme.exists() else ""
    new = with_files_table(text, files_table(dirs))
    if new is None:
        print(f"{readme}: no {FILES_MARKER} markers", file=sys.stderr)
        return 1
    if new != text:
        if args.check:
            stale.append(readme)
        else:
            readme.write_text(new)
            print(f"wrote the {FILES_MARKER} table of {readme.relative_to(args.root)}")
    if renames:
        print("hunks that only change names (normalise them in renamed()):\n  " + "\n  ".join(renames),
              file=sys.stderr)
    if stale:
        print("stale chapter diffs or files table (run fem-tools docs diffs):\n  " +
              "\n  ".join(str(p.relative_to(args.root)) for p in stale), file=sys.stderr)
    if stale or renames:
        return 1
    if args.check:
        print(f"{len(dirs) - 1} chapter diffs are current, none with a hunk of names only")
    return 0
