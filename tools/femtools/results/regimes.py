"""The regime sweep's results (results/regimes.json, written by fem-tools runs regimes): the schema
check, the quantities read from it (chapter 01's CG iterations and phase shares, speedups over
chapter 01, the solve table's ratios) and the generated statements that place each of the
poster's six numbers in the regime where it holds. Shared by runs/regimes.py, docs/update.py and
the tests; the schema is documented in README.md beside the bench schema."""
from femtools.docs import provenance
from femtools.docs.markdown import table
from femtools.results import poster
from femtools.results.common import BASELINE
from femtools.results.phases import parts
from femtools.results.schema import validate_bench

SOLVER_KEYS = set(poster.SOLVE_RATIOS)
# The phases that share chapter 01's step; "other" is the rest of the step (copies, the
# velocity and position update, the profiler).
SHARE_PHASES = parts()
HEADER_KEYS = ["scene", "steps", "warmup_steps", "dt", "cg_tolerance", "cg_max_iterations",
               "build", "machine", "commit", "schema_version"]


def validate_regimes(data):
    """Problems of a regimes.json: the sweep's own keys, then every point as a bench.json (the
    header's keys with the point's mesh, material, chapters and solvers), every point with the
    same chapters, chapter 01 among them."""
    if not isinstance(data, dict):
        return ["the top level is not an object"]
    problems = [f"regimes: missing '{k}'" for k in
                ["knob", "bodies", "E_values", "points"] + HEADER_KEYS if k not in data]
    if problems:
        return problems
    if data["knob"] != "E":
        problems.append(f"regimes.knob: expected 'E', got {data['knob']!r}")
    points = data["points"]
    if not isinstance(points, list) or not points:
        return problems + ["regimes.points: expected a non-empty list"]
    names = None
    for i, p in enumerate(points):
        where = f"points[{i}]"
        if not isinstance(p, dict):
            problems.append(f"{where}: not an object")
            continue
        e = p.get("E")
        if not isinstance(e, (int, float)) or isinstance(e, bool) or not e > 0:
            problems.append(f"{where}.E: expected a positive number, got {e!r}")
        if p.get("body") not in data["bodies"]:
            problems.append(f"{where}.body: {p.get('body')!r} is not one of regimes.bodies")
        bench = {k: data[k] for k in HEADER_KEYS}
        bench.update({k: p[k] for k in ("mesh", "material", "chapters", "solvers") if k in p})
        problems += [f"{where}: {q}" for q in validate_bench(bench)]
        chapters = [c.get("chapter") for c in p.get("chapters", []) if isinstance(c, dict)]
        if BASELINE not in chapters:
            problems.append(f"{where}: no {BASELINE} (the baseline of every ratio)")
        if names is not None and chapters != names:
            problems.append(f"{where}: chapters {chapters} differ from points[0]'s {names}")
        names = names if names is not None else chapters
    for body in data["bodies"]:
        have = sorted(p.get("E") for p in points if isinstance(p, dict) and p.get("body") == body)
        if have != sorted(data["E_values"]):
            problems.append(f"regimes: body {body} has E values {have}, expected {data['E_values']}")
    return problems


def chapter(point, name):
    return next((c for c in point["chapters"] if c["chapter"] == name), None)


def baseline(point):
    return chapter(point, BASELINE)


def iterations(point):
    """Chapter 01's median CG iterations: the sweep's x axis."""
    return baseline(point)["cg_iterations"]


def share(point, phase):
    """The share of `phase` in chapter 01's median step ('other': what the phases leave)."""
    ms = baseline(point)["median_ms"]
    if phase == "other":
        return max(0.0, 1.0 - sum(ms[p] for p in SHARE_PHASES) / ms["step"])
    return ms[phase] / ms["step"]


def speedup(point, name, phase="step"):
    c, base = chapter(point, name), baseline(point)
    return base["median_ms"][phase] / max(c["median_ms"][phase], 1e-12) if c else None


def solver_ratio(point, name):
    """Eigen solve()'s median time over the named solver's, on the same systems."""
    solvers = {s["name"]: s for s in point.get("solvers", [])}
    if "eigen_cg" not in solvers or name not in solvers:
        return None
    return solvers["eigen_cg"]["median_ms"] / max(solvers[name]["median_ms"], 1e-12)


def chapter_names(data):
    return [c["chapter"] for c in data["points"][0]["chapters"]]


def body_points(data, body):
    return sorted((p for p in data["points"] if p["body"] == body), key=iterations)


def value(point, key, name):
    """The measured counterpart of the poster's number `key` at a point; name: a chapter (for
    the phases), ignored for the solve table's two ratios."""
    return solver_ratio(point, key) if key in SOLVER_KEYS else speedup(point, name, key)


def best_chapter(point, key):
    """The chapter with the highest ratio for a phase at this point (not chapter 01)."""
    # A chapter without the phase (0 ms: chapter 08's df/dx, fused into its element pass) has
    # no ratio for it, not an infinite one.
    others = [c["chapter"] for c in point["chapters"]
              if c["chapter"] != BASELINE and c["median_ms"].get(key, 1.0) > 0]
    return max(others, key=lambda n: speedup(point, n, key)) if others else BASELINE


def where(point):
    return f"{iterations(point):g} it., solve {100 * share(point, 'solve'):.0f}%"


def describe(points, target, measure):
    """A short phrase: at which of a body's points (sorted by chapter 01's iterations)
    `measure` reaches `target`. measure(point) -> (ratio, chapter reaching it or '')."""
    values = [measure(p) for p in points]
    reached = [v >= target for v, _ in values]

    def at(i):
        who = f" `{values[i][1][:2]}`" if values[i][1] else ""
        return f"x{values[i][0]:.3g}{who} at {where(points[i])}"
    if all(reached):
        return f"**everywhere** (at least {at(min(range(len(values)), key=lambda i: values[i][0]))})"
    if not any(reached):
        return f"nowhere (at most {at(max(range(len(values)), key=lambda i: values[i][0]))})"
    first = reached.index(True)
    last = len(reached) - 1 - reached[::-1].index(True)
    if all(reached[first:]):
        return (f"**from {where(points[first])} up** (x{values[first][0]:.3g} there); "
                f"below, at most x{max(v for v, _ in values[:first]):.3g}")
    if all(reached[:last + 1]):
        return (f"**up to {where(points[last])}** (x{values[last][0]:.3g} there); "
                f"above, at most x{max(v for v, _ in values[last + 1:]):.3g}")
    lo, hi = min(v for v, _ in values), max(v for v, _ in values)
    return (f"at {sum(reached)} of {len(points)} points, not ordered by the regime "
            f"(x{lo:.3g} to x{hi:.3g})")


def first_reached(data, key, target):
    """The lowest chapter-01 iteration count at which any chapter reaches `target`, with the
    body and the chapter; None if no point reaches it."""
    hits = []
    for p in data["points"]:
        name = best_chapter(p, key)
        if speedup(p, name, key) >= target:
            hits.append((iterations(p), p["body"], name, speedup(p, name, key)))
    return min(hits) if hits else None


def poster_rows(data):
    """(poster number, who is measured, one phrase per body) for each of the six numbers."""
    rows = []
    bodies = data["bodies"]
    have06 = chapter(data["points"][0], poster.POSTER_CHAPTER) is not None
    for key, label, target in poster.NUMBERS:
        number = f"{label} x{target:g}"
        if key in SOLVER_KEYS:
            if all(p.get("solvers") for p in data["points"]):
                rows.append((number, f"`{key}`, the same systems",
                             [describe(body_points(data, b), target, lambda p: (solver_ratio(p, key), ""))
                              for b in bodies]))
            else:
                rows.append((number, "not measured (--no-solvers)", ["-"] * len(bodies)))
            continue
        if have06:
            rows.append((number, "chapter 06 (the poster's optimized stepper)",
                         [describe(body_points(data, b), target,
                                   lambda p: (speedup(p, poster.POSTER_CHAPTER, key), "")) for b in bodies]))
        rows.append(("" if have06 else number, "the fastest chapter at each point",
                     [describe(body_points(data, b), target,
                               lambda p: (speedup(p, best_chapter(p, key), key), best_chapter(p, key)))
                      for b in bodies]))
    return rows


def poster_statements(data):
    """Markdown: for each of the poster's six numbers, the regime (chapter 01's CG iterations
    and the solve's share of its step, per body) where the repository reaches it and where not,
    and the iteration count at which the overall step first reaches x9.849."""
    header = ["the poster's number", "measured"] + [f"`{b}`" for b in data["bodies"]]
    lines = [table(header, [[number, who] + cells for number, who, cells in poster_rows(data)],
                   ["---"] * len(header)).rstrip("\n")]
    target = poster.number("step")
    hit = first_reached(data, "step", target)
    forces = sorted((share(p, "forces"), p) for p in data["points"])
    (low, p_low), (high, p_high) = forces[0], forces[-1]
    e = data["E_values"]
    lines += ["", (f"The overall step first reaches x{target:g} at {hit[0]:g} iterations of chapter "
                   f"01's CG (`{hit[1]}`, chapter `{hit[2]}`, x{hit[3]:.3g})." if hit else
                   f"No chapter reaches the overall step's x{target:g} at any point of the sweep.") +
              f" Sweep: E from {min(e):g} to {max(e):g} Pa at dt = {data['dt']:g} s, {data['scene']}, "
              f"{data['steps']} measured steps per point, CG tolerance {data['cg_tolerance']:g}, "
              f"{provenance.of_run(data)}; "
              f"x{target:g} and the rest are medians' ratios over chapter 01 (\"it.\": chapter 01's "
              "median CG iterations; \"solve\": the solve's share of chapter 01's median step).",
              "", f"Amdahl's bound: chapter 01's forces phase (rotations and element forces) takes from "
              f"{100 * low:.0f}% (`{p_low['body']}`, {where(p_low)}) to {100 * high:.0f}% (`{p_high['body']}`, "
              f"{where(p_high)}) of its step, so a chapter that leaves that phase as it is cannot make the "
              f"step more than x{1 / high:.3g} faster where it weighs most (x{1 / low:.3g} where it weighs "
              f"least), however fast the rest; x{target:g} needs it under {100 / target:.1f}%."]
    return "\n".join(lines) + "\n"
