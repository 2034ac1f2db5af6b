"""The roofline's remainder, named (`fem_lessons roofline`'s data "kernels_alone", written by
apps/roofline/kernels_alone.cpp): per chapter and thread count, the solve's measured time, its
bound, its dominant kernels run alone on data already in the cache, and the solve's time beyond
its bound in two: in the core (the kernels alone beyond their own bound) and between the kernels
(the solve beyond its kernels alone and the rest's bound). `fem-tools docs lessons` writes it
between the markers roofline-kernels-alone of the lesson's page; data recorded before the
measurement existed give a line that says so."""
from femtools.docs.markdown import ms, table

MARKER = "roofline-kernels-alone"
NOT_RECORDED = ("*Not recorded: the committed roofline data predate the kernels alone "
                "(`./tutorial.sh roofline` records them).*\n")


def run_name(r):
    return f"`{r['chapter']}@{r['threads']}`"


def share(bound_s, seconds):
    return f"{100 * bound_s / max(seconds, 1e-12):.0f}%" + (
        " (faster than its bound)" if bound_s > seconds else "")


def kernels_cell(r):
    """Each kernel alone: its share of its own bound (the bound over the time it took), and where
    it ran faster than the bound allows, that it did: a count of bytes that the kernel reads from
    a nearer level than its working set's (a chunk's vectors reread in L1), or a roof measured
    low. The V-cycle's kernels below its fine smoothing step (each level's smoothing step, the
    transfers, the coarsest solve: names that start with "level") in one entry, their time per
    solve against their bounds, so that a row stays readable however deep the hierarchy."""
    own = [k for k in r["kernels"] if not k["kernel"].startswith("level ")]
    levels = [k for k in r["kernels"] if k["kernel"].startswith("level ")]
    cells = [f"{k['kernel']} {share(k['bound_s'], k['seconds'])}" for k in own]
    if levels:
        bound = sum(k["bound_s"] * k["calls"] for k in levels)
        seconds = sum(k["seconds"] * k["calls"] for k in levels)
        cells.append(f"the levels' transfers, coarse levels and coarsest solve ({len(levels)} "
                     f"kernels, {ms(1e3 * seconds)} ms a solve) {share(bound, seconds)}")
    return "; ".join(cells)


def larger(r):
    """Which of the two halves of the remainder is the larger one."""
    return "in the core" if r["in_core_s"] >= r["between_s"] else "between the kernels"


def section(data, where=None):
    """The Markdown between the markers, from the lesson's data (a dict, or None); where: the
    machine, compiler and commit they were recorded on (femtools.docs.provenance)."""
    runs = (data or {}).get("kernels_alone")
    if not runs:
        return NOT_RECORDED
    rows = [[run_name(r), ms(1e3 * r["solve_s"]), ms(1e3 * r["solve_bound_s"]),
             f"{ms(1e3 * r['alone_s'])} ({ms(1e3 * r['parts_bound_s'])})", ms(1e3 * r["in_core_s"]),
             ms(1e3 * r["between_s"]), ms(1e3 * r["waiting_s"]), kernels_cell(r)] for r in runs]
    header = ["chapter", "solve, ms", "its bound, ms", "kernels alone, ms (their bound)",
              "in the core, ms", "between the kernels, ms", "the solve's waiting, ms",
              "each kernel alone: of its bound"]
    larger_part = "; ".join(f"{run_name(r)} {larger(r)}" for r in runs)
    return (table(header, rows, ["---"] + ["---:"] * 6 + ["---"]) +
            f"\nThe larger part of each solve's remainder, on this machine: {larger_part}."
            + (f" Recorded on {where}." if where else "") + "\n")
