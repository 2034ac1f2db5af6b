"""Chapter 10's reference: PyAMG's smoothed aggregation on the same filtered systems.

For each mesh, runs `fem_lessons multigrid --export` (chapter 10 for some steps, then the last step's
filtered system S A S + I - S, its right-hand side and the filtered rigid-body modes as
Matrix Market), builds pyamg.smoothed_aggregation_solver with the rigid-body modes as B and
its defaults otherwise (symmetric strength with theta 0, standard aggregation, Jacobi-smoothed
prolongator, symmetric block Gauss-Seidel), and runs PyAMG's CG with one V-cycle as the
preconditioner from a zero guess, with the stopping rule of ours: ||r|| < tol ||b||. Prints
a Markdown table of the iteration counts beside chapter 10's and the block-Jacobi PCG's (chapter 09)
on the same system, also from a zero guess.

    fem-tools runs pyamg --tool build/release/fem_lessons
    fem-tools runs pyamg --json docs/data/lessons/pyamg.json
    fem-tools runs pyamg --options --meshes plate_poster    # PyAMG's own settings on one system
(the second also records the table, which fem-tools docs lessons writes into chapter 10's
README between its pyamg-table markers)
"""
import json
import pathlib
import subprocess
import sys
import tempfile

from femtools.args import command_parser
from femtools.docs.markdown import table
from femtools.docs.markers import replace_between
from femtools.paths import ROOT
from femtools.files import write_text
DEFAULT_MESHES = ["plate_poster", "beam_500", "beam_1k", "beam_2k", "beam_5k", "beam_10k"]


def mesh_path(name):
    for folder in (ROOT / "meshes", ROOT / "meshes" / "generated"):
        if (folder / f"{name}.msh").exists():
            return folder / f"{name}.msh"
    raise SystemExit(f"pyamg_reference: no mesh {name}.msh in meshes/ or meshes/generated/ "
                     "(./tutorial.sh meshes --large generates the large beams)")


def pyamg_iterations(folder, tol, modes):
    import numpy as np
    import pyamg
    import scipy.io
    import scipy.sparse

    A = scipy.sparse.csr_matrix(scipy.io.mmread(folder / "A.mtx"))
    b = np.asarray(scipy.io.mmread(folder / "b.mtx")).ravel()
    B = np.asarray(scipy.sparse.csr_matrix(scipy.io.mmread(folder / "B.mtx")).todense())[:, :modes]
    # The fixed nodes' rows of B are zero; PyAMG needs B's columns independent on each
    # aggregate and handles the rest itself. Blocks of 3: one node's unknowns together.
    A = scipy.sparse.bsr_matrix(A, blocksize=(3, 3))
    ml = pyamg.smoothed_aggregation_solver(A, B=B, symmetry="hermitian", max_coarse=30)
    residuals = []
    x, info = pyamg.krylov.cg(A, b, x0=np.zeros_like(b), tol=tol, criteria="rr", maxiter=2000,
                              M=ml.aspreconditioner(cycle="V"), residuals=residuals)
    if info != 0:
        raise SystemExit(f"pyamg_reference: PyAMG's CG did not converge (info {info})")
    return len(residuals) - 1, len(ml.levels), ml.operator_complexity()


# --options: PyAMG's settings on one system against the chapters' choice (Chebyshev of degree 3,
# every connection a strong one, a Jacobi-smoothed prolongator, the coarsest level at most 200
# unknowns), each as keyword arguments of smoothed_aggregation_solver.
def _chebyshev(degree):
    return ("chebyshev", {"degree": degree, "iterations": 1})


OPTION_ROWS = [
    ("Chebyshev degree 3, strength theta 0, smoothed P (the chapters' choice)", {}),
    ("Chebyshev degree 2", {"presmoother": _chebyshev(2), "postsmoother": _chebyshev(2)}),
    ("Chebyshev degree 4", {"presmoother": _chebyshev(4), "postsmoother": _chebyshev(4)}),
    ("symmetric Gauss-Seidel", {"presmoother": ("gauss_seidel", {"sweep": "symmetric"}),
                                "postsmoother": ("gauss_seidel", {"sweep": "symmetric"})}),
    ("strength theta 0.02", {"strength": ("symmetric", {"theta": 0.02})}),
    ("strength theta 0.1", {"strength": ("symmetric", {"theta": 0.1})}),
    ("strength theta 0.25", {"strength": ("symmetric", {"theta": 0.25})}),
    ("evolution strength", {"strength": "evolution"}),
    ("unsmoothed P = T", {"smooth": None}),
    ("energy-minimizing P", {"smooth": "energy"}),
    ("coarsest at most 30", {"max_coarse": 30}),
]


def _passes(smoother):
    """Matrix passes of one pre- or post-smoothing (a symmetric Gauss-Seidel sweep is two)."""
    name, options = smoother
    if name == "chebyshev":
        return options["degree"]
    return 2 if options.get("sweep") == "symmetric" else 1


def pyamg_options(folder, tol):
    """Per row of OPTION_ROWS: levels, CG iterations from zero, operator complexity and the
    V-cycle's matrix passes per PCG iteration in units of the finest matrix (the CG's product,
    each level's smoothing and residual, the coarsest level's dense solve as its n^2 entries)."""
    import numpy as np
    import pyamg
    import scipy.io
    import scipy.sparse

    A = scipy.sparse.bsr_matrix(scipy.sparse.csr_matrix(scipy.io.mmread(folder / "A.mtx")),
                                blocksize=(3, 3))
    b = np.asarray(scipy.io.mmread(folder / "b.mtx")).ravel()
    B = np.asarray(scipy.sparse.csr_matrix(scipy.io.mmread(folder / "B.mtx")).todense())
    rows = []
    for name, changes in OPTION_ROWS:
        options = {"B": B, "symmetry": "hermitian", "max_coarse": 200,
                   "presmoother": _chebyshev(3), "postsmoother": _chebyshev(3), **changes}
        ml = pyamg.smoothed_aggregation_solver(A, **options)
        residuals = []
        _, info = pyamg.krylov.cg(A, b, x0=np.zeros_like(b), tol=tol, criteria="rr", maxiter=2000,
                                  M=ml.aspreconditioner(cycle="V"), residuals=residuals)
        if info != 0:
            raise SystemExit(f"pyamg_reference: {name}: PyAMG's CG did not converge (info {info})")
        fine = ml.levels[0].A.nnz
        passes = _passes(options["presmoother"]) + _passes(options["postsmoother"]) + 1
        work = 1.0 + sum(level.A.nnz / fine * passes for level in ml.levels[:-1])
        work += ml.levels[-1].A.shape[0] ** 2 / fine
        rows.append((name, len(ml.levels), len(residuals) - 1, ml.operator_complexity(), work))
    return rows


def options_table(mesh, rows, tol, steps, scene):
    reference = rows[0][2] * rows[0][4]
    lines = [table(["PyAMG on " + mesh, "levels", "CG iterations", "operator complexity",
                    "passes per iteration", "passes per solve"],
                   [[name, levels, iterations, f"{complexity:.2f}", f"{work:.1f}",
                     f"{iterations * work:.0f} (x{iterations * work / reference:.2f})"]
                    for name, levels, iterations, complexity, work in rows])]
    lines.append(f"PCG from a zero guess to ||r|| < {tol:g} ||b|| on the filtered system of step "
                 f"{steps} of the {scene} scene; a pass reads one finest matrix's non-zeros. "
                 f"Generated by `fem-tools runs pyamg --options --meshes {mesh}`.")
    return "\n".join(lines) + "\n"


def export_system(args, name, folder):
    """Chapter 10 for --steps steps on the mesh, its last filtered system written into folder;
    returns chapter 10's summary of it."""
    print(f"{name}: chapter 10 for {args.steps} steps, export", file=sys.stderr, flush=True)
    subprocess.run([args.tool, "multigrid", "--mesh", str(mesh_path(name)), "--scene", args.scene,
                    "--steps", str(args.steps), "--tol", str(args.tol),
                    "--modes", str(args.modes), "--threads", "1", "--export", str(folder)],
                   check=True, stdout=subprocess.DEVNULL)
    return json.loads((folder / "summary.json").read_text())


def main(argv=None, prog=None):
    parser = command_parser(prog, __doc__)
    parser.add_argument("--tool", default=str(ROOT / "build" / "release" / "fem_lessons"))
    parser.add_argument("--meshes", default=",".join(DEFAULT_MESHES), help="comma-separated")
    parser.add_argument("--scene", default="cantilever")
    parser.add_argument("--steps", type=int, default=10, help="steps before the system is taken")
    parser.add_argument("--tol", type=float, default=1e-4)
    parser.add_argument("--modes", type=int, choices=(3, 6), default=6)
    parser.add_argument("--options", action="store_true",
                        help="instead: PyAMG's smoother, strength, prolongator and coarsest size "
                             "on the first mesh's system, iterations and matrix passes each")
    parser.add_argument("--readme", help="also write the table between the pyamg-table markers")
    parser.add_argument("--json", help="also write the table as docs/data/lessons/pyamg.json "
                                       "(fem-tools docs lessons puts it into the README)")
    args = parser.parse_args(argv)
    if args.steps <= 0 or not 0 < args.tol < 1:
        parser.error("--steps must be positive and --tol in (0, 1)")
    if not pathlib.Path(args.tool).exists():
        parser.error(f"no {args.tool}: build it first (cmake --build --preset release "
                     "--target fem_lessons)")

    if args.options and (args.readme or args.json):
        parser.error("--options prints its table only: leave out --readme and --json")
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for name in args.meshes.split(","):
            folder = pathlib.Path(tmp) / name
            ours = export_system(args, name, folder)
            if args.options:
                rows = pyamg_options(folder, args.tol)
                print(options_table(name, rows, args.tol, args.steps, args.scene), end="")
                return 0
            print(f"{name}: PyAMG", file=sys.stderr, flush=True)
            iterations, levels, complexity = pyamg_iterations(folder, args.tol, args.modes)
            rows.append((name, ours["nodes"], ours["ours_iterations"], ours["ours_levels"],
                         iterations, levels, complexity, ours["block_jacobi_iterations"]))

    header = ["mesh", "nodes", "chapter 10 iterations (levels)",
              "PyAMG SA iterations (levels, operator complexity)", "ratio", "chapter 09 block Jacobi"]
    lines = [table(header, [[f"`{name}`", nodes, f"{ours} ({our_levels})", f"{theirs} ({levels}, {complexity:.2f})",
                             f"{ours / theirs:.2f}", jacobi]
                            for name, nodes, ours, our_levels, theirs, levels, complexity, jacobi in rows])]
    lines.append(f"PCG from a zero guess to ||r|| < {args.tol:g} ||b|| on the filtered system of "
                 f"step {args.steps} of the {args.scene} scene, {args.modes} modes per aggregate. "
                 f"Generated by `fem-tools runs pyamg --meshes {args.meshes}`.")
    text = "\n".join(lines) + "\n"
    print(text, end="")
    if args.readme:
        readme = pathlib.Path(args.readme)
        written = replace_between(readme.read_text(), "pyamg-table", text)
        if written is None:
            raise SystemExit(f"fem-tools runs pyamg: {readme} has no pyamg-table markers")
        readme.write_text(written)
        print(f"wrote {args.readme}")
    if args.json:
        record = {"schema_version": 1, "lesson": "pyamg", "chapter": "10_multigrid",
                  "readme": "chapters/10_multigrid/README.md", "marker": "pyamg-table",
                  "command": "fem-tools runs pyamg " + " ".join(sys.argv[1:] if argv is None else argv), "table": text}
        write_text(args.json, json.dumps(record, indent=2) + "\n")
        print(f"wrote {args.json}")
