#!/usr/bin/env python3
"""Regenerates the tutorial's meshes with the gmsh Python API.

Every mesh is a box meshed with linear tetrahedra, some with round holes drilled through
them (the perforated bar: a volumetric body of the poster's size that is not a thin plate,
the second benchmark body of the regime sweep). The only physical group is the volume,
so the saved file holds the tetrahedra (a file whose only physical group is a surface
saves none). Options are fixed (one thread, fixed algorithms) so that a run with the
same gmsh version reproduces the same files.

    .venv/bin/python meshes/generate.py              # the committed meshes
    .venv/bin/python meshes/generate.py --large      # also the scaling meshes (not committed)
    .venv/bin/python meshes/generate.py --only beam_1k plate_poster
    .venv/bin/python meshes/generate.py --list       # names, sizes, node and tet counts
    .venv/bin/python meshes/generate.py --readme     # rewrite the table in meshes/README.md
"""
import argparse
import pathlib
import sys
import time

from femtools.files import replacing, write_text

HERE = pathlib.Path(__file__).resolve().parent

# name: (box size x, y, z in metres, target mesh size, committed?)
MESHES = {
    "test_beam": ((1.0, 0.1, 0.1), 0.05, True),
    "plate_poster": ((1.0, 1.0, 0.05), 0.036, True),
    "beam_500": ((1.0, 0.1, 0.1), 0.036, True),
    "beam_1k": ((1.0, 0.1, 0.1), 0.025, True),
    "beam_2k": ((1.0, 0.1, 0.1), 0.0195, True),
    "beam_5k": ((1.0, 0.1, 0.1), 0.0132, True),
    "beam_10k": ((1.0, 0.1, 0.1), 0.0102, True),
    "beam_20k": ((1.0, 0.1, 0.1), 0.0082, False),
    "beam_50k": ((1.0, 0.1, 0.1), 0.0060, False),
    "beam_100k": ((1.0, 0.1, 0.1), 0.0047, False),
    "perforated_bar_poster": ((1.0, 0.2, 0.2), 0.0288, True),
    "perforated_bar_test": ((1.0, 0.2, 0.2), 0.07, True),
}
# name: (number of holes, radius in metres): cylinders along y through the box, evenly spaced
# along x, centred in z. The faces at min/max x, y and z stay flat and whole, so the scenes'
# bounding-box selections (clamped face, floor, pushed edge) find the same kind of nodes as
# on a box. perforated_bar_test is the same body, coarse, for the tests.
HOLES = {
    "perforated_bar_poster": (5, 0.07),
    "perforated_bar_test": (5, 0.07),
}


def generate(gmsh, name, path):
    (lx, ly, lz), size, _ = MESHES[name]
    gmsh.clear()
    gmsh.model.add(name)
    volumes = [drill(gmsh, gmsh.model.occ.addBox(0.0, 0.0, 0.0, lx, ly, lz), (lx, ly, lz), *HOLES[name])
               if name in HOLES else gmsh.model.occ.addBox(0.0, 0.0, 0.0, lx, ly, lz)]
    gmsh.model.occ.synchronize()
    gmsh.model.addPhysicalGroup(3, volumes, name="body")
    gmsh.option.setNumber("Mesh.MeshSizeMin", size)
    gmsh.option.setNumber("Mesh.MeshSizeMax", size)
    gmsh.model.mesh.generate(3)
    # Under a temporary name, renamed over the mesh once whole: gmsh writes in place, and a
    # Ctrl-C (gmsh puts SIGINT back to its default) would leave a committed mesh cut.
    with replacing(path) as tmp:
        gmsh.write(str(tmp))
    tags, _ = gmsh.model.mesh.getElementsByType(4)
    _, nodes = gmsh.model.mesh.getElementsByType(4)
    return len(set(nodes.tolist())), len(tags)


def drill(gmsh, box, dims, holes, radius):
    """Cuts `holes` cylinders of `radius` along y through the box; returns the volume's tag."""
    lx, ly, lz = dims
    tools = [(3, gmsh.model.occ.addCylinder(lx * (k + 1) / (holes + 1), -ly, lz / 2, 0.0, 3 * ly, 0.0, radius))
             for k in range(holes)]
    out, _ = gmsh.model.occ.cut([(3, box)], tools)
    if len(out) != 1:
        sys.exit(f"drilling {holes} holes of radius {radius} left {len(out)} volumes, not one")
    return out[0][1]


def configure(gmsh):
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.option.setNumber("General.NumThreads", 1)
    gmsh.option.setNumber("Mesh.Algorithm", 6)  # Frontal-Delaunay for the surfaces
    gmsh.option.setNumber("Mesh.Algorithm3D", 1)  # Delaunay
    gmsh.option.setNumber("Mesh.Optimize", 1)
    gmsh.option.setNumber("Mesh.RandomSeed", 1)
    gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
    gmsh.option.setNumber("Mesh.Binary", 0)
    gmsh.option.setNumber("Mesh.SaveAll", 0)


def count(gmsh, path):
    gmsh.clear()
    gmsh.open(str(path))
    tags, nodes = gmsh.model.mesh.getElementsByType(4)
    return len(set(nodes.tolist())), len(tags)


def readme_table(rows, version):
    lines = ["| file | body (m) | mesh size (m) | nodes | tets | committed |",
             "| --- | --- | ---: | ---: | ---: | --- |"]
    for name, nodes, tets in rows:
        (lx, ly, lz), size, committed = MESHES[name]
        where = "yes" if committed else "no: `--large`, into `meshes/generated/`"
        holes = f", {HOLES[name][0]} holes of radius {HOLES[name][1]:g}" if name in HOLES else ""
        lines.append(f"| `{name}.msh` | {lx:g} x {ly:g} x {lz:g}{holes} | {size:g} | {nodes} | {tets} | {where} |")
    lines.append("")
    lines.append(f"Generated with gmsh {version} by `meshes/generate.py`.")
    return "\n".join(lines) + "\n"


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--only", nargs="+", metavar="NAME", help="only these meshes")
    parser.add_argument("--large", action="store_true", help="also the large scaling meshes")
    parser.add_argument("--out", type=pathlib.Path, help="output directory (default: meshes/, "
                        "meshes/generated/ for the large ones)")
    parser.add_argument("--list", action="store_true", help="print name, nodes, tets of existing files")
    parser.add_argument("--readme", action="store_true", help="rewrite the table in meshes/README.md")
    args = parser.parse_args()

    names = [n for n, (_, _, committed) in MESHES.items() if committed or args.large]
    if args.only:
        unknown = [n for n in args.only if n not in MESHES]
        if unknown:
            parser.error(f"unknown mesh {', '.join(unknown)} (known: {', '.join(MESHES)})")
        names = args.only

    import gmsh  # imported late so that --help works without it
    gmsh.initialize(readConfigFiles=False)
    configure(gmsh)

    def path_of(name):
        folder = args.out or (HERE if MESHES[name][2] else HERE / "generated")
        folder.mkdir(parents=True, exist_ok=True)
        return folder / f"{name}.msh"

    rows = []
    for name in names:
        path = path_of(name)
        if args.list or args.readme:
            if not path.exists():
                print(f"{name}: {path} is missing (run without --list to generate it)", file=sys.stderr)
                continue
            nodes, tets = count(gmsh, path)
        else:
            start = time.time()
            nodes, tets = generate(gmsh, name, path)
            print(f"{name:14s} size {MESHES[name][1]:<7g} {nodes:7d} nodes {tets:7d} tets "
                  f"{time.time() - start:6.1f} s  -> {path}", flush=True)
        if args.list:
            print(f"{name:14s} {nodes:7d} nodes {tets:7d} tets")
        rows.append((name, nodes, tets))

    if args.readme:
        readme = HERE / "README.md"
        text = readme.read_text()
        begin, end = "<!-- meshes:begin -->", "<!-- meshes:end -->"
        if begin not in text or end not in text:
            sys.exit(f"{readme} has no {begin} ... {end} markers")
        head, rest = text.split(begin, 1)
        _, tail = rest.split(end, 1)
        write_text(readme, head + begin + "\n" + readme_table(rows, gmsh.__version__) + end + tail)
        print(f"wrote the table in {readme}")
    gmsh.finalize()


if __name__ == "__main__":
    main()
