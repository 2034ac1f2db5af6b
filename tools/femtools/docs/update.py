"""Regenerates every results table in the docs from the results JSON, between marker
comments (never typed by hand). Each section is found by its markers in README.md, docs/*.md
and the chapters' READMEs, wherever it stands:

  from bench.json          results:machine, results:phases, results:speedups, results:allocations,
                           results:solvers, headline, chapter-map, bench-table:<chapter row>
  from scaling.json        results:scaling, and in a chapter's README scaling-per-node and
                           scaling-pair (that chapter beside the chapter it builds on)
  from bench.json and      fewer-waits (chapter 13 against 12, and the roofline's price of the
  lessons/roofline.json    waits it removes)
  from viewer.json         viewer-fps
  from threads.json        threads-table
  from regimes.json        regimes:poster, regimes:points, regimes:solvers (results/regimes.json,
                           copied to docs/data/regimes.json; without it, docs/data/regimes.json)

The JSON behind the committed docs is committed too, in docs/data/ (bench.json, and
scaling.json, viewer.json, threads.json when they were run): `./tutorial.sh docs` copies a new
run there first; without one of the optional files its sections stay as they are. --check
writes nothing and fails when a generated section differs from what the committed JSON gives
(ctest label docs).

    fem-tools docs update                  # from docs/data/bench.json
    fem-tools docs update --images docs/images   # also copy the plots
    fem-tools docs update --check          # are the docs those of docs/data?
"""
import pathlib
import shutil
import sys

from femtools.args import command_parser, add_root_option
from femtools.course import parents
from femtools.docs import fewer_waits, regime_tables, tables
from femtools.docs.diffs import chapter_dirs
from femtools.docs.markers import update_file
from femtools.results import regimes as regimes_common
from femtools.results.common import ResultsError, chapter_dir, die, load
from femtools.results.schema import load_checked

# The sections of a chapter's README that set the chapter beside the chapter it builds on (its
# recipe's parent), over the beam series: the marker names the table, the README's folder the chapters.
CHAPTER_SCALING = {"scaling-per-node": tables.per_node_scaling, "scaling-pair": tables.pair_scaling}


def doc_files(root):
    """Every file a generated section may stand in."""
    return [root / "README.md", *sorted((root / "docs").glob("*.md")),
            *sorted((root / "chapters").glob("*/README.md"))]


def update_regimes(root, path, images, stale=None):
    """The regime sweep's generated sections (results/regimes.json, kept as docs/data/regimes.json,
    the JSON behind the committed docs): without a sweep, the committed sections stay."""
    data_copy = root / "docs" / "data" / "regimes.json"
    source = path or root / "results" / "regimes.json"
    if not source.exists():
        if path is not None or not data_copy.exists():
            print(f"no {source}: the regime sections stay as they are (./tutorial.sh regimes)")
            return
        source = data_copy
    try:
        reg = load(source)
    except ResultsError as e:
        die(f"fem-tools docs update: {e}")
    problems = regimes_common.validate_regimes(reg)
    if problems:
        die(f"fem-tools docs update: {source} does not match the regimes schema:\n  " + "\n  ".join(problems))
    if source.resolve() != data_copy.resolve() and stale is None:
        data_copy.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(source, data_copy)
        print(f"copied {source.name} to {data_copy.parent}")
    poster = regimes_common.poster_statements(reg)
    sections = {"regimes:poster": poster, "regimes:points": regime_tables.regimes_points_table(reg),
                "regimes:solvers": regime_tables.regimes_solvers_table(reg)}
    for path in doc_files(root):
        update_file(path, sections, stale)
    if stale is not None:
        return
    png = source.with_name("regimes.png")
    if images and png.exists() and source != data_copy:
        images = images if images.is_absolute() else root / images
        images.mkdir(parents=True, exist_ok=True)
        shutil.copy(png, images / png.name)
        print(f"copied {png.name} to {images}")


def load_all(args, data_dir):
    """bench.json and the optional scaling, viewer and threads records (None where not run)."""
    optional = {"scaling": (args.scaling, dict(scaling=True)), "viewer": (args.viewer, dict(viewer=True)),
                "threads": (args.threads, {})}
    try:
        loaded = {"bench": load_checked(args.bench or data_dir / "bench.json")}
        for name, (path, kind) in optional.items():
            path = path or data_dir / f"{name}.json"
            loaded[name] = load_checked(path, **kind) if path.exists() else None
    except ResultsError as e:
        die(f"fem-tools docs update: {e}")
    return loaded


def bench_sections(root, data, scaling, check):
    """The sections from bench.json (and the scaling table of docs/results.md)."""
    # A chapter's title is its README's heading (chapters/registry.cmake): read it from there, so
    # that a heading rewritten since the benchmark ran shows in the chapter map at once.
    for c in data["chapters"]:
        c["title"] = tables.readme_title(root, c["chapter"], c.get("title", ""))
    sections = {
        "results:machine": tables.machine_table(data), "results:phases": tables.phases_table(data),
        "results:speedups": tables.speedups_table(data), "results:allocations": tables.allocations_table(data),
        "results:solvers": tables.solvers_table(data),
        "headline": tables.headline(data), "chapter-map": tables.chapter_map(root, data)}
    sections.update({f"bench-table:{c['chapter']}": tables.chapter_table(root, data, c["chapter"])
                     for c in data["chapters"]})
    # The scaling run takes tens of minutes and is optional: without results/scaling.json the
    # committed table stays as it is (a placeholder goes in only where there is no table yet).
    if scaling is not None or "run `./tutorial.sh scaling`" in (root / "docs" / "results.md").read_text():
        sections["results:scaling"] = tables.scaling_table(scaling)
    elif not check:
        print("no docs/data/scaling.json: the scaling table in docs/results.md is left as it is")
    return sections


def chapter_sections(root, scaling):
    """Per course chapter's README, its sections that set it beside the chapter it builds on."""
    sections = {}
    for this in chapter_dirs(root)[1:]:
        base = parents.parent_of(root, this.name)
        note = tables.base_note(root, this.name, base)
        sections[this / "README.md"] = {name: make(scaling, base, this.name, note)
                                        for name, make in CHAPTER_SCALING.items()}
    return sections


def update_all(root, loaded, stale):
    """Writes (or, with a list stale, checks) every section the data give, wherever it stands."""
    data, scaling = loaded["bench"], loaded["scaling"]
    sections = bench_sections(root, data, scaling, stale is not None)
    # Like the scaling table, the viewer's and the threads' are kept as they are without a run.
    if loaded["viewer"] is not None:
        sections["viewer-fps"] = tables.viewer_table(loaded["viewer"])
    if loaded["threads"] is not None:
        sections["threads-table"] = tables.threads_table(loaded["threads"], data)
    roofline = root / "docs" / "data" / "lessons" / "roofline.json"
    sections["fewer-waits"] = fewer_waits.section(data, load(roofline) if roofline.exists() else None)
    per_chapter = chapter_sections(root, scaling) if scaling is not None else {}
    for path in doc_files(root):
        update_file(path, own_sections(root, path, {**sections, **per_chapter.get(path, {})}), stale)


def own_sections(root, path, sections):
    """What one file takes of the sections: a chapter's README only its own rows' bench tables,
    and a student's variant (a copy of its original's README, with the original's markers) only
    those and the solve table, as a README of its own rows."""
    chapter = path.parent
    if chapter.parent != root / "chapters":
        return sections
    mine = {k for k in sections if k.startswith("bench-table:") and chapter_dir(k[12:]) == chapter.name}
    if (chapter / "variant_of").exists():
        return {k: v for k, v in sections.items() if k in mine or (mine and k == "results:solvers")}
    return {k: v for k, v in sections.items() if not k.startswith("bench-table:") or k in mine}


def copy_images(root, images, source_dir):
    images = images if images.is_absolute() else root / images
    images.mkdir(parents=True, exist_ok=True)
    for png in sorted(source_dir.glob("*.png")):
        shutil.copy(png, images / png.name)
        print(f"copied {png.name} to {images}")


def main(argv=None, prog=None):
    parser = command_parser(prog, __doc__)
    add_root_option(parser)
    parser.add_argument("--bench", type=pathlib.Path, help="default: ROOT/docs/data/bench.json")
    parser.add_argument("--scaling", type=pathlib.Path, help="default: ROOT/docs/data/scaling.json if present")
    parser.add_argument("--viewer", type=pathlib.Path, help="default: ROOT/docs/data/viewer.json if present")
    parser.add_argument("--threads", type=pathlib.Path, help="default: ROOT/docs/data/threads.json if present")
    parser.add_argument("--regimes", type=pathlib.Path,
                        help="default: ROOT/results/regimes.json, else ROOT/docs/data/regimes.json")
    parser.add_argument("--check", action="store_true",
                        help="write nothing; exit 1 if a generated section differs from the JSON")
    parser.add_argument("--images", type=pathlib.Path, nargs="?", const=pathlib.Path("docs/images"),
                        help="copy the PNG plots from the results directory here (default docs/images)")
    parser.add_argument("--only-regimes", action="store_true",
                        help="only the regime sweep's sections (no results/bench.json needed)")
    args = parser.parse_args(argv)
    root, data_dir = args.root, args.root / "docs" / "data"
    if args.only_regimes:
        return update_regimes(root, args.regimes, args.images)
    bench_path = args.bench or data_dir / "bench.json"
    stale = [] if args.check else None
    update_all(root, load_all(args, data_dir), stale)
    if not args.check:
        if args.images:
            copy_images(root, args.images, bench_path.parent)
        return update_regimes(root, args.regimes, args.images)
    # The regime sections are checked against the committed sweep only.
    update_regimes(root, args.regimes or data_dir / "regimes.json", None, stale)
    for s in stale:
        print(f"stale: {s} differs from what {bench_path} gives", file=sys.stderr)
    if stale:
        print("fem-tools docs update --check: regenerate with `fem-tools docs update`", file=sys.stderr)
        return 1
    print(f"fem-tools docs update --check: every generated section matches {bench_path}")
    return 0
