"""The regime sweep's generated tables (docs/data/regimes.json): its points and its solve table;
the poster's statements are results/regimes.py's."""
from femtools.docs import provenance
from femtools.docs.markdown import ms, ratio, table
from femtools.results import poster
from femtools.results import regimes as regimes_common
from femtools.results.common import BASELINE


def regimes_points_table(reg):
    """One row per point of the regime sweep: chapter 01's CG iterations and solve share, the
    overall step's speedup of every chapter over 01, and the solve table's two poster ratios."""
    names = [n for n in regimes_common.chapter_names(reg) if n != BASELINE]
    rows = []
    for body in reg["bodies"]:
        for p in regimes_common.body_points(reg, body):
            ratios = [regimes_common.solver_ratio(p, k) for k in ("eigen_cg_guess", "pcg_ch06")]
            rows.append([f"`{body}`", f"{p['E']:g}", f"{regimes_common.iterations(p):g}",
                         f"{100 * regimes_common.share(p, 'solve'):.0f}%", ms(p["chapters"][0]["median_ms"]["step"])] +
                        [f"x{regimes_common.speedup(p, n):.2f}" for n in names] +
                        [f"x{r:.2f}" if r else "-" for r in ratios])
    return (table(["body", "E (Pa)", "01's CG it.", "solve share of 01's step", "01's step (ms)"] +
                  [f"`{n[:2]}`" for n in names] + ["`solveWithGuess()`", "our PCG"], rows,
                  ["---"] + ["---:"] * (len(names) + 6)) + f"\nRecorded on {provenance.of_run(reg)}.\n")


def regimes_solvers_table(reg):
    """The whole solve table at the softest and the stiffest point of each body."""
    shown = []
    for body in reg["bodies"]:
        pts = regimes_common.body_points(reg, body)
        shown += [pts[0], pts[-1]] if len(pts) > 1 else pts
    if not all(p.get("solvers") for p in shown):
        return "(the sweep ran with --no-solvers)\n"
    names = [s["name"] for s in shown[0]["solvers"]]
    rows = []
    for n in names:
        cells = []
        for p in shown:
            s = next(x for x in p["solvers"] if x["name"] == n)
            cells.append(f"{ms(s['median_ms'])} ({ratio(p['solvers'][0]['median_ms'], s['median_ms'])}, "
                         f"{s['iterations']:g} it., {s['allocations_per_solve']:g} alloc.)")
        reported = poster.SOLVE_MS.get(n)
        rows.append([f"`{n}`"] + cells + [f"{reported:g} ms" if reported else "-"])
    header = [f"`{p['body']}`, E = {p['E']:g} (01: {regimes_common.iterations(p):g} it.)" for p in shown]
    ends = "; ".join(
        f"`{body}`: x{regimes_common.solver_ratio(pts[0], 'pcg_ch06'):.2f} at the softest point, "
        f"x{regimes_common.solver_ratio(pts[-1], 'pcg_ch06'):.2f} at the stiffest"
        for body, pts in ((b, regimes_common.body_points(reg, b)) for b in reg["bodies"]))
    return (table(["solver: median ms (vs `eigen_cg`, iterations, allocations)"] + header + ["poster"], rows) +
            f"\nOur PCG over Eigen's `solve()` (poster x{poster.number('pcg_ch06'):g}): {ends}. "
            f"{provenance.of_run(reg)}.\n")
