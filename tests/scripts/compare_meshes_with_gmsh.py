"""Every committed mesh read by the course's reader (common/msh_read.cpp, through the msh_dump
program) and by gmsh's Python API, compared exactly: the same node tags with the same doubles,
the same tetrahedra (tags and node tags) in the same order. Each mesh is compared as committed
(MSH 4.1), saved by gmsh as MSH 2.2, and with its nodes renumbered by gmsh (RCMK, as chapter 11's
renumbered meshes: the file lists the nodes out of tag order).

usage: compare_meshes_with_gmsh.py MSH_DUMP MESH_FOLDER SCRATCH
Exits 77 (ctest: skipped, not passed) when gmsh's Python package does not import.
"""
import pathlib
import subprocess
import sys

SKIP = 77


def course_reading(dump, path):
    """(node tags, coordinates, tet tags, tet node tags) as msh_dump prints them."""
    lines = subprocess.run([dump, str(path)], check=True, capture_output=True,
                           text=True).stdout.splitlines()
    nodes = int(lines[0].split()[1])
    node_rows = [line.split() for line in lines[1:1 + nodes]]
    tet_rows = [line.split() for line in lines[2 + nodes:]]
    assert lines[1 + nodes] == f"tets {len(tet_rows)}", lines[1 + nodes]
    return ([int(r[0]) for r in node_rows], [tuple(float(x) for x in r[1:]) for r in node_rows],
            [int(r[0]) for r in tet_rows], [tuple(int(n) for n in r[1:]) for r in tet_rows])


def gmsh_reading(gmsh, path):
    """The same, from gmsh's API: getNodes sorted by tag, getElementsByType(4) as listed."""
    gmsh.clear()
    gmsh.open(str(path))
    tags, coords, _ = gmsh.model.mesh.getNodes(-1, -1, False, False)
    tet_tags, tet_nodes = gmsh.model.mesh.getElementsByType(4)
    xyz = [tuple(float(x) for x in coords[3 * k:3 * k + 3]) for k in range(len(tags))]
    order = sorted(range(len(tags)), key=lambda k: int(tags[k]))
    return ([int(tags[k]) for k in order], [xyz[k] for k in order], [int(t) for t in tet_tags],
            [tuple(int(n) for n in tet_nodes[4 * e:4 * e + 4]) for e in range(len(tet_tags))])


def forms(gmsh, mesh, scratch):
    """The mesh as committed, saved as MSH 2.2, and renumbered (MSH 4.1), each a path."""
    yield mesh
    gmsh.clear()
    gmsh.open(str(mesh))
    gmsh.option.setNumber("Mesh.MshFileVersion", 2.2)
    msh22 = scratch / f"{mesh.stem}_22.msh"
    gmsh.write(str(msh22))
    yield msh22
    gmsh.clear()
    gmsh.open(str(mesh))
    old, new = gmsh.model.mesh.computeRenumbering("RCMK")
    gmsh.model.mesh.renumberNodes(old, new)
    gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
    renumbered = scratch / f"{mesh.stem}_rcmk.msh"
    gmsh.write(str(renumbered))
    yield renumbered


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    dump, folder, scratch = sys.argv[1], pathlib.Path(sys.argv[2]), pathlib.Path(sys.argv[3])
    try:
        import gmsh
    except ImportError as e:
        print(f"SKIP: gmsh's Python package does not import here ({e}): the course's reader was "
              "not compared with gmsh's (pip install -r requirements.txt installs it)")
        return SKIP
    meshes = sorted(folder.glob("*.msh"))
    if not meshes:
        sys.exit(f"FAIL: no .msh file in {folder}")
    scratch.mkdir(parents=True, exist_ok=True)
    gmsh.initialize()
    failed, files, nodes, tets = [], 0, 0, 0
    try:
        gmsh.option.setNumber("General.Verbosity", 1)  # errors only
        for mesh in meshes:
            for path in forms(gmsh, mesh, scratch):
                ours, theirs = course_reading(dump, path), gmsh_reading(gmsh, path)
                files, nodes, tets = files + 1, nodes + len(ours[0]), tets + len(ours[2])
                for name, a, b in zip(("node tags", "coordinates", "tet tags", "tet nodes"),
                                      ours, theirs):
                    if a != b:
                        first = next((k for k, (x, y) in enumerate(zip(a, b)) if x != y),
                                     min(len(a), len(b)))
                        failed.append(f"{path.name}: {name} differ at {first} "
                                      f"({len(a)} ours, {len(b)} gmsh's)")
    finally:
        gmsh.finalize()
    for line in failed:
        print("FAIL:", line)
    if failed:
        return 1
    print(f"PASS: {files} files ({len(meshes)} committed meshes, each as committed, as MSH 2.2 "
          f"and renumbered): {nodes} nodes and {tets} tetrahedra read identically by the "
          "course's reader and by gmsh")
    return 0


if __name__ == "__main__":
    sys.exit(main())
