"""Chapter 13 beside chapter 12, as the committed data measure it (docs/data/bench.json and
docs/data/lessons/roofline.json), written between the markers fewer-waits of chapter 13's README
by `fem-tools docs update`: the lines the chapter's text reads instead of typing numbers."""
from femtools.docs import provenance
from femtools.docs.markdown import ms, ratio
from femtools.docs.tables import chapters_by_name


def section(data, roofline):
    """Chapter 13 against chapter 12, as measured: the step's speedup at one thread (the control:
    no waits to save) and at two, with each row's quartiles, the price the roofline puts on
    the waits chapter 13 removes (docs/data/lessons/roofline.json: each run's "waiting_s", the
    step's barriers and regions times their measured price on a spinning team), and what the
    control's difference is made of (control_line)."""
    by = chapters_by_name(data)
    rows = {t: (by.get(f"12_half_the_bytes@{t}"), by.get(f"13_fewer_waits@{t}")) for t in (1, 2)}
    if not all(a and b for a, b in rows.values()):
        return "(no chapters 12 and 13 at 1 and 2 threads in docs/data/bench.json)\n"

    def step(c):
        return f"{ms(c['median_ms']['step'])} [{ms(c['q1_ms']['step'])}, {ms(c['q3_ms']['step'])}]"

    lines = [f"- {t} thread{'s' if t > 1 else ''}: {ratio(a['median_ms']['step'], b['median_ms']['step'])} over "
             f"chapter 12; steps {step(a)} and {step(b)} ms (median [quartiles], 12 and 13)"
             for t, (a, b) in rows.items()]
    recorded = (roofline or {}).get("data") or {}
    runs = {r["chapter"]: r for r in recorded.get("runs", [])
            if r.get("threads") == 2 and r.get("mesh") == data["mesh"]["file"]}
    a, b = runs.get("12_half_the_bytes"), runs.get("13_fewer_waits")
    if a and b:
        saved = 1e3 * (a["waiting_s"] - b["waiting_s"])
        lines.append(f"- the waits removed, priced by the roofline at 2 threads: {saved:.3f} ms a step, "
                     f"{100 * saved / (1e3 * a['step_s']):.1f}% of chapter 12's")
    lines += control_line(recorded, data["mesh"]["file"])
    roof = provenance.of_run(roofline) if roofline and len(lines) > 2 else None
    where = f"; the roofline's lines {roof}" if roof and roof != provenance.of_run(data) else ""
    return "\n".join(lines) + f"\n\n{data['mesh']['file']}; {provenance.of_run(data)}{where}.\n"


def control_line(recorded, mesh):
    """Chapter 13 at one thread, where there are no waits to save, against chapter 12 in the
    roofline's kernels-alone split: what its extra vector passes add to the solve's bound, what
    the solve measured, and how much of that lies between the kernels."""
    alone = {r["chapter"]: r for r in recorded.get("kernels_alone", [])
             if r.get("threads") == 1 and r.get("mesh") == mesh}
    a, b = alone.get("12_half_the_bytes"), alone.get("13_fewer_waits")
    if not (a and b):
        return []
    bound, solve, between = (1e3 * (b[k] - a[k]) for k in ("solve_bound_s", "solve_s", "between_s"))
    return [f"- the control at 1 thread, 13's solve minus 12's in the roofline's run: bound {bound:+.3f} ms, "
            f"measured {solve:+.3f} ms, between the kernels {between:+.3f} ms"]
