"""fem-tools: the course's Python tooling behind one command line.

    fem-tools GROUP COMMAND [OPTIONS]      (or: .venv/bin/python -m femtools GROUP COMMAND)
    fem-tools GROUP --help                 the group's commands
    fem-tools GROUP COMMAND --help         the command's options

`fem-tools` serves the repository it is run in: where .venv's package is another tree's (a
second worktree or a copy of the repository sharing the .venv), it runs the package of the tree
around the working directory instead.

Each command is one module (femtools/GROUP/MODULE.py) with a main(argv, prog); it is imported
only when it runs, so that `fem-tools check sizes` does not load matplotlib."""
import importlib
import os
import pathlib
import sys

from femtools.paths import ROOT

# group -> command -> (module under femtools., what it does); the order is the one --help lists.
COMMANDS = {
    "results": {
        "validate": ("results.validate", "check a bench, scaling or regimes JSON against its schema"),
    },
    "docs": {
        "update": ("docs.update", "write the generated tables of the docs from docs/data/ (--check)"),
        "lessons": ("docs.lessons", "write the lesson tables of docs/data/lessons/ into the READMEs (--check)"),
        "diffs": ("docs.diffs", "write docs/diffs/ and the chapter-files table; a variant's diff (--check)"),
        "book": ("docs.book", "docs/data/book.json: the sitting and the code the data were recorded from"),
    },
    "plots": {
        "bench": ("plots.bench", "the plots of a run's bench.json (or --scaling, --threads)"),
        "roofline": ("plots.roofline", "the roofline plot of fem_lessons roofline --json"),
        "figures": ("plots.figures", "the figures of chapters 10-12 from docs/data/figures/ and the code"),
        "gif": ("plots.gif", "a fem_sim VTK series rendered to an animated GIF"),
    },
    "runs": {
        "scaling": ("runs.scaling", "the chapters over the beam series: results/scaling.json"),
        "regimes": ("runs.regimes", "the regime sweep over Young's modulus: results/regimes.json"),
        "viewer-fps": ("runs.viewer_fps", "the viewer's frame rate per chapter, headless: results/viewer.json"),
        "pyamg": ("runs.pyamg", "chapter 10's reference: PyAMG's smoothed aggregation on the same systems"),
        "renumber-meshes": ("runs.renumber_meshes", "gmsh's own node orders of the meshes, for chapter 11"),
    },
    "course": {
        "variant": ("course.variant", "copy a chapter under a new name (a variant to change and measure)"),
        "handin": ("course.handin", "check a student's hand-in: sources, diff, tests, plots"),
        "compare": ("course.compare", "a run beside another: speedups, spread, what differs"),
    },
    "check": {
        "sizes": ("checks.sizes", "no file over 400 lines, no function over 60, no type over 17 members"),
        "chapter-sources": ("checks.chapter_sources", "no chapter source names another chapter"),
        "doc-numbers": ("checks.doc_numbers", "no measured number in a docs table outside the markers"),
        "vectorized": ("checks.vectorized", "every omp simd loop of a source vectorized (GCC's report)"),
        "warnings": ("checks.compile_warnings", "zero warnings at x86-64-v3 and -v4 (compile only)"),
    },
}
HELP = ("-h", "--help")


def usage(groups, out):
    print(__doc__.split("\n\n")[1].rstrip("\n") if len(groups) > 1 else
          f"usage: fem-tools {groups[0]} COMMAND [OPTIONS]", file=out)
    for group in groups:
        print(f"\n{group}:", file=out)
        for command, (_, what) in COMMANDS[group].items():
            print(f"  {command:<16} {what}", file=out)


def tree_around_cwd():
    """The repository around the working directory (the nearest folder up with tools/femtools)."""
    here = pathlib.Path.cwd().resolve()
    return next((d for d in (here, *here.parents) if (d / "tools" / "femtools" / "cli.py").is_file()), None)


def run_in_own_tree(args):
    """Runs the command with the package of the tree around the working directory, when that is
    not this package's (once: the new process does not redirect again)."""
    tree = tree_around_cwd()
    if tree is None or tree == ROOT or os.environ.get("FEMTOOLS_REDIRECTED"):
        return
    path = os.pathsep.join(p for p in (str(tree / "tools"), os.environ.get("PYTHONPATH")) if p)
    env = dict(os.environ, PYTHONPATH=path, FEMTOOLS_REDIRECTED="1")
    os.execve(sys.executable, [sys.executable, "-m", "femtools", *args], env)


def main(argv=None):
    args = sys.argv[1:] if argv is None else list(argv)
    run_in_own_tree(args)
    if not args or args[0] in HELP:
        usage(list(COMMANDS), sys.stdout if args else sys.stderr)
        return 0 if args else 2
    group = args[0]
    if group not in COMMANDS:
        print(f"fem-tools: unknown group '{group}' (one of {', '.join(COMMANDS)})", file=sys.stderr)
        return 2
    if len(args) < 2 or args[1] in HELP:
        usage([group], sys.stdout if len(args) > 1 else sys.stderr)
        return 0 if len(args) > 1 else 2
    command = args[1]
    if command not in COMMANDS[group]:
        print(f"fem-tools {group}: unknown command '{command}' (one of {', '.join(COMMANDS[group])})",
              file=sys.stderr)
        return 2
    module = importlib.import_module("femtools." + COMMANDS[group][command][0])
    return module.main(args[2:], prog=f"fem-tools {group} {command}") or 0
