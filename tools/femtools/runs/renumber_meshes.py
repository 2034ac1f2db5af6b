"""gmsh's own node orders, the library reference of chapter 11: writes a copy of each mesh
with its nodes renumbered by gmsh.model.mesh.computeRenumbering (methods RCMK, Hilbert and,
where gmsh was built with it, Metis) into meshes/generated/NAME_METHOD.msh (git ignores it).
`fem_lessons node-order` measures them beside the chapter's own orders.

    fem-tools runs renumber-meshes                         # the default meshes
    fem-tools runs renumber-meshes --meshes plate_poster --methods RCMK"""
import pathlib
import sys

from femtools.args import command_parser
from femtools.paths import ROOT
DEFAULT_MESHES = "plate_poster,beam_10k,beam_100k"
METHODS = ("RCMK", "Hilbert", "Metis")


def mesh_path(name):
    committed = ROOT / "meshes" / f"{name}.msh"
    return committed if committed.exists() else ROOT / "meshes" / "generated" / f"{name}.msh"


def renumber(gmsh, source, target, method):
    gmsh.clear()
    gmsh.open(str(source))
    old, new = gmsh.model.mesh.computeRenumbering(method)
    gmsh.model.mesh.renumberNodes(old, new)
    gmsh.write(str(target))


def main(argv=None, prog=None):
    parser = command_parser(prog, __doc__)
    parser.add_argument("--meshes", default=DEFAULT_MESHES,
                        help=f"comma-separated mesh names (default {DEFAULT_MESHES}); a missing "
                             "generated mesh is skipped with a note (./tutorial.sh meshes --large)")
    parser.add_argument("--methods", default="RCMK,Hilbert",
                        help=f"comma-separated gmsh methods, of {', '.join(METHODS)} (default RCMK,Hilbert)")
    parser.add_argument("--out", type=pathlib.Path, default=ROOT / "meshes" / "generated")
    args = parser.parse_args(argv)
    methods = args.methods.split(",")
    unknown = [m for m in methods if m not in METHODS]
    if unknown:
        parser.error(f"unknown method {', '.join(unknown)} (gmsh knows {', '.join(METHODS)})")
    import gmsh  # after the arguments: --help works without gmsh
    args.out.mkdir(parents=True, exist_ok=True)
    gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Verbosity", 1)  # errors only
        for name in args.meshes.split(","):
            source = mesh_path(name)
            if not source.exists():
                print(f"fem-tools runs renumber-meshes: no {source.relative_to(ROOT)}, skipped "
                      "(./tutorial.sh meshes --large)", file=sys.stderr)
                continue
            for method in methods:
                target = args.out / f"{name}_{method.lower()}.msh"
                try:
                    renumber(gmsh, source, target, method)
                except Exception as e:  # gmsh raises a bare Exception for a method it lacks
                    print(f"fem-tools runs renumber-meshes: {name} by {method}: {e}", file=sys.stderr)
                    continue
                print(f"wrote {target}", flush=True)
    finally:
        gmsh.finalize()
    return 0
