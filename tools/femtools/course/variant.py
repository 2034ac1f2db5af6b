"""Makes a variant of a chapter: a copy under a new name, for a change to measure against the
original in one benchmark run. The build finds it (chapters/registry.cmake), the generic tests
check it (tests/generic/), and the generated-diff check leaves it out.

    fem-tools course variant 06 my_fused_updates     # chapters/06_my_fused_updates/

The copy's namespace fem::ch06 becomes fem::ch06_my_fused_updates (both are linked into the
same programs), its includes of its own headers point to the copy, its README's heading names
it, and chapters/06_my_fused_updates/variant_of names the original."""
import re
import shutil
import sys

from femtools.args import command_parser, add_root_option

# fullmatch, not match with $: $ also matches before a final newline, and a name ending in one
# made a folder that broke every later build (build.ninja cannot hold a newline).
NAME = re.compile(r"[a-z][a-z0-9_]*")
MAX_NAME = 64


class VariantError(Exception):
    pass


def find_original(chapters, number):
    number = number.zfill(2)
    found = [d for d in sorted(chapters.iterdir())
             if d.is_dir() and d.name.startswith(number + "_") and (d / "stepper.hpp").exists()
             and not (d / "variant_of").exists()]
    if len(found) != 1:
        known = ", ".join(d.name[:2] for d in sorted(chapters.iterdir())
                          if (d / "stepper.hpp").exists() and not (d / "variant_of").exists())
        raise VariantError(f"no chapter {number} to copy (chapters: {known})")
    return found[0]


def rewrite(text, original, variant, number):
    """The copy's own names: its directory in includes, its namespace chNN everywhere."""
    text = text.replace(f"chapters/{original}/", f"chapters/{variant}/")
    return re.sub(rf"\bch{number}\b", f"ch{number}_{variant[3:]}", text)


def unrewrite(text, original, variant, number):
    """The inverse of rewrite: the variant's text in the original's names, so that a diff's
    context lines read as the original's code and only the student's change stands out."""
    text = text.replace(f"chapters/{variant}/", f"chapters/{original}/")
    return re.sub(rf"\bch{number}_{re.escape(variant[3:])}\b", f"ch{number}", text)


def readme_heading(text, original, variant):
    lines = text.splitlines(keepends=True)
    title = re.sub(r"^# Chapter [^:]+:\s*", "", lines[0]).strip() if lines else original
    heading = (f"# Chapter {variant}: a variant of {original} ({title})\n\n"
               f"A copy of [{original}](../{original}/README.md) made with `./tutorial.sh variant`. "
               f"Say here what you changed and why; `./tutorial.sh diff {variant}` "
               f"shows the change.\n")
    return heading + "".join(lines[1:])


def make_variant(root, number, name):
    if len(name) > MAX_NAME:  # the folder's name would pass the file system's limit part-way
        raise VariantError(f"'{name[:20]}...' ({len(name)} characters) is not a variant name: at most "
                           f"{MAX_NAME} characters (it names a folder, a namespace and build targets)")
    if not NAME.fullmatch(name):
        raise VariantError(f"'{name}' is not a variant name: lower-case letters, digits and _, "
                           "starting with a letter")
    chapters = root / "chapters"
    original = find_original(chapters, number)
    variant = f"{original.name[:2]}_{name}"
    target = chapters / variant
    if target.exists():
        raise VariantError(f"{target.relative_to(root)} exists already")
    number = original.name[:2]
    target.mkdir()
    for source in sorted(original.iterdir()):
        if not source.is_file():
            continue
        text = source.read_text()
        if source.name == "README.md":
            text = readme_heading(text, original.name, variant)
        (target / source.name).write_text(rewrite(text, original.name, variant, number))
        shutil.copymode(source, target / source.name)
    (target / "variant_of").write_text(original.name + "\n")
    return original.name, variant


def main(argv=None, prog=None):
    parser = command_parser(prog, __doc__)
    parser.add_argument("chapter", help="the number of the chapter to copy, e.g. 06")
    parser.add_argument("name", help="the variant's name, e.g. my_fused_updates")
    add_root_option(parser, hidden=True)
    args = parser.parse_args(argv)
    try:
        original, variant = make_variant(args.root, args.chapter, args.name)
    except VariantError as e:
        print(f"fem-tools course variant: {e}", file=sys.stderr)
        return 2
    sources = sorted(p.name for p in (args.root / "chapters" / variant).iterdir()
                     if p.suffix in (".cpp", ".hpp"))
    print(f"""made chapters/{variant}/, a copy of chapters/{original}/ (namespace fem::ch{variant})
next:
  edit the file(s) your change is in: {", ".join(sources)}
  ./tutorial.sh test -L ch{variant}                   # the checks every chapter passes
  ./tutorial.sh bench --chapters {original[:2]},{variant} --no-solvers --out results/{args.name}
  ./tutorial.sh diff {args.name}                   # your change, the copy's renames undone""")
    return 0
