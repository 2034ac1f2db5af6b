"""The poster's numbers, the one home of them: what the repository's measurements are set
beside (docs/results.md, README.md, the plots, the regime sweep)."""
from femtools.results.phases import PHASE_LABELS

# The chapter the poster's "optimized" column corresponds to (its own PCG, zero allocations).
POSTER_CHAPTER = "06_custom_pcg"
# Its reported speedups of the optimized stepper over the naive one, per phase.
SPEEDUPS = {"dfdx": 5.487, "compose": 21.358, "constraints": 218.79, "step": 9.849}
# Its solve table: milliseconds per solve, and the two ratios over Eigen's solve() as printed.
SOLVE_MS = {"eigen_cg": 7.1, "eigen_cg_guess": 4.39, "pcg_ch06": 1.68}
SOLVE_RATIOS = {"eigen_cg_guess": 1.614, "pcg_ch06": 4.226}
# The six numbers as the regime sweep places them: (key, what it is, the number as printed).
NUMBERS = [(phase, PHASE_LABELS[phase], speedup) for phase, speedup in SPEEDUPS.items()] + [
    ("eigen_cg_guess", "Eigen `solveWithGuess()` over `solve()`", SOLVE_RATIOS["eigen_cg_guess"]),
    ("pcg_ch06", "our PCG over Eigen's `solve()`", SOLVE_RATIOS["pcg_ch06"]),
]
# The poster's numbers were measured on the cantilever on a mesh of the poster's size: they
# are drawn beside a run only when the run is that one (any other mesh or scene would compare
# unlike with unlike).
MESH, SCENE = "plate_poster.msh", "cantilever"


def number(key):
    """The poster's number `key` as printed (a phase's speedup or a solver's ratio)."""
    return next(target for k, _, target in NUMBERS if k == key)


def comparable(data):
    """Whether a run is the poster's (its mesh and scene)."""
    return data.get("mesh", {}).get("file") == MESH and data.get("scene") == SCENE
