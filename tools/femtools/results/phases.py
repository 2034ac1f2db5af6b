"""The phases of a step, the one list in Python: common/stepper.hpp's StepProfile::phases() is
the one in C++, and a bench.json carries it as "phases" (read from there where a run has it; a
run recorded before it has these)."""
# In fem_bench's order; the last, "step", is the whole step, the others its parts.
ALL_PHASES = ["forces", "dfdx", "compose", "constraints", "solve", "step"]
PHASE_LABELS = {
    # common/'s element kernels in chapters 01-07; chapter 08's fused element pass, which
    # also does the work of df/dx construction and most of the composition (its dfdx is 0)
    "forces": "forces",
    "dfdx": "df/dx construction",
    "compose": "system composition",
    "constraints": "constraints",
    "solve": "solve",
    "step": "overall step",
}
# How the plots draw a phase: its colour in the stacked bars, its marker on the roofline.
PHASE_STYLE = {
    "forces": ("tab:gray", "o"),
    "dfdx": ("tab:orange", "s"),
    "compose": ("tab:green", "^"),
    "constraints": ("tab:red", "v"),
    "solve": ("tab:blue", "D"),
}
# The phase the speedup tables and plots leave out: forces, the element kernels, which from
# chapter 08 on also do the work of df/dx and composition (a speedup of it alone says little).
NOT_COMPARED = "forces"


def all_phases(data=None):
    """The run's phases in order, the whole step last: its own list where it carries one."""
    listed = (data or {}).get("phases")
    return list(listed) if listed else list(ALL_PHASES)


def parts(data=None):
    """The phases that make up the step (all but the whole step)."""
    return all_phases(data)[:-1]


def compared(data=None):
    """The phases whose speedups the tables and plots compare."""
    return [p for p in all_phases(data) if p != NOT_COMPARED]


def label(phase):
    return PHASE_LABELS.get(phase, phase)


def colour(phase):
    return PHASE_STYLE.get(phase, ("0.5", "x"))[0]


def marker(phase):
    return PHASE_STYLE.get(phase, ("0.5", "x"))[1]
