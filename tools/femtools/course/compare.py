"""A run beside another: "my numbers don't match the book". For every chapter both runs
measured and every phase, the speedup over chapter 01 in each run, side by side; a difference
larger than the runs' own spread is marked (the speedup's range from the quartiles fem_bench
records: q1 of chapter 01 over q3 of the chapter up to q3 over q1; marked when the two runs'
ranges do not overlap). Beside them, what differs in the two records: the instruction set the
build targets and the one the CPU offers, cores, caches, compiler, flags, the load during the
run, the mesh and the scene. A plot of both runs' speedups goes beside RUN (compare.png).

    fem-tools course compare results                      # against the committed docs/data/bench.json
    fem-tools course compare results/bench.json other/bench.json --out /tmp
    ./tutorial.sh compare RUN [REFERENCE]

Prints the records' differences, the table and one line "differs: CHAPTER PHASE ..." per
marked difference; exits 0 (a comparison, not a check) unless a file cannot be read."""
import pathlib

from femtools.args import command_parser
from femtools.results.common import BASELINE, ResultsError, cache_summary, die, machine_summary
from femtools.results.phases import PHASE_LABELS, compared
from femtools.results.schema import load_checked
from femtools.files import replacing

from femtools.paths import ROOT
REFERENCE = ROOT / "docs" / "data" / "bench.json"


def bench_path(path):
    path = pathlib.Path(path)
    return path / "bench.json" if path.is_dir() else path


def record_fields(data):
    """What a ratio depends on, as (label, value) in the order printed."""
    m, b, mesh = data["machine"], data["build"], data.get("mesh", {})
    load = (f"{m['other_cpus']:.2g} cores used by others" + (" (busy)" if m.get("busy") else "")
            if m.get("other_cpus") is not None else "not recorded")
    return [("CPU", m.get("model_name", m["cpu"])),
            ("instruction set (build)", m.get("isa_build", "not recorded")),
            ("instruction set (CPU)", m.get("isa_cpu", "not recorded")),
            ("cores / threads", machine_summary(m).split(", ", 1)[-1] if "isa_build" in m
             else f"? / {m.get('threads', '?')}"),
            ("caches", cache_summary(m) or "not recorded"),
            ("memory", f"{m['memory_bytes'] / 2**30:.0f} GiB" if m.get("memory_bytes", -1) > 0
             else "not recorded"),
            ("compiler", b["compiler"]), ("flags", b["flags"]), ("build type", b["build_type"]),
            ("Eigen", b["eigen"]), ("load during the run", load),
            ("mesh", f"{mesh.get('file', '?')} ({mesh.get('nodes', '?')} nodes)"),
            ("scene", data["scene"]), ("steps", str(data.get("steps", "?"))),
            ("commit", data.get("commit", "?"))]


def record_differences(run, reference):
    return [(label, a, b) for (label, a), (_, b) in zip(record_fields(run), record_fields(reference))
            if a != b]


def speedups(data):
    """{(chapter, phase): (median, low, high)}: the speedup over chapter 01 and its range from
    the quartiles. A phase a chapter does not have (0 ms) has no speedup."""
    rows = {c["chapter"]: c for c in data["chapters"]}
    base = rows.get(BASELINE)
    if base is None:
        return {}
    out = {}
    for name, c in rows.items():
        for phase in compared(data):
            med, q1, q3 = (c[key][phase] for key in ("median_ms", "q1_ms", "q3_ms"))
            b_med, b_q1, b_q3 = (base[key][phase] for key in ("median_ms", "q1_ms", "q3_ms"))
            if min(med, q1, b_med, b_q1) > 0:
                out[(name, phase)] = (b_med / med, b_q1 / q3, b_q3 / q1)
    return out


def compare(run, reference):
    """[(chapter, phase, run's speedup triple, reference's, marked)] for the rows both hold, in
    the run's order."""
    ours, theirs = speedups(run), speedups(reference)
    rows = []
    for c in run["chapters"]:
        for phase in compared(run) if c["chapter"] != BASELINE else []:
            key = (c["chapter"], phase)
            if key in ours and key in theirs:
                a, b = ours[key], theirs[key]
                rows.append((*key, a, b, a[1] > b[2] or b[1] > a[2]))
    return rows


def print_table(rows, phases):
    chapters = list(dict.fromkeys(r[0] for r in rows))
    cell = {(r[0], r[1]): f"{r[2][0]:.2f} | {r[3][0]:.2f}{' *' if r[4] else '  '}" for r in rows}
    width = max(len(c) for c in chapters) + 2
    print(f"\nspeedup over {BASELINE} (median step of each phase), this run | the reference; "
          "* : the two differ by more than their quartile ranges")
    print("chapter".ljust(width) + "".join(PHASE_LABELS.get(p, p)[:19].ljust(21) for p in phases))
    for chapter in chapters:
        print(chapter.ljust(width) +
              "".join(cell.get((chapter, p), "-").ljust(21) for p in phases))


def plot(rows, phases, differences, run_name, reference_name, path):
    from femtools.plots import pyplot
    plt = pyplot()
    import numpy as np
    shown = [p for p in phases if any(r[1] == p for r in rows)]
    fig, axes = plt.subplots(len(shown), 1, figsize=(10, 2.2 * len(shown) + 1), squeeze=False)
    for ax, phase in zip(axes[:, 0], shown):
        mine = [r for r in rows if r[1] == phase]
        x = np.arange(len(mine))
        for offset, index, label, color in ((-0.2, 2, run_name, "tab:blue"),
                                            (0.2, 3, reference_name, "0.6")):
            med = np.array([r[index][0] for r in mine])
            err = np.array([[m - r[index][1], r[index][2] - m] for m, r in zip(med, mine)]).T
            ax.bar(x + offset, med, 0.4, yerr=err, color=color, label=label, capsize=2)
        for i, r in enumerate(mine):
            if r[4]:
                ax.annotate("*", (i, max(r[2][2], r[3][2])), ha="center", va="bottom", color="firebrick")
        ax.set_yscale("log")
        ax.set_xticks(x, [r[0] for r in mine], rotation=30, ha="right", fontsize=7)
        ax.set_ylabel(f"{PHASE_LABELS[phase]}\nspeedup", fontsize=8)
    axes[0, 0].legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    fig.suptitle(f"Speedup over {BASELINE}: {run_name} beside {reference_name} "
                 "(bars: quartile range; *: beyond it)", fontsize=9)
    note = "; ".join(f"{label}: {a} | {b}" for label, a, b in differences
                     if label not in ("flags", "commit")) or "the records agree"
    fig.text(0.01, 0.005, f"what differs ({run_name} | {reference_name}): {note}", fontsize=6.5,
             color="0.35", ha="left", va="bottom", wrap=True)
    fig.tight_layout(rect=(0, 0.05, 1, 1))
    with replacing(path) as tmp:
        fig.savefig(tmp, dpi=110)
    plt.close(fig)


def main(argv=None, prog=None):
    parser = command_parser(prog, __doc__)
    parser.add_argument("run", help="a run's folder or its bench.json")
    parser.add_argument("reference", nargs="?", default=str(REFERENCE),
                        help="another run (default: the committed docs/data/bench.json)")
    parser.add_argument("--out", type=pathlib.Path, help="where compare.png goes (default: beside RUN)")
    args = parser.parse_args(argv)
    paths = [bench_path(args.run), bench_path(args.reference)]
    try:
        run, reference = (load_checked(p) for p in paths)
    except ResultsError as e:
        die(str(e))
    print(f"this run:      {paths[0]}\nthe reference: {paths[1]}")
    differences = record_differences(run, reference)
    print("\nwhat differs in the two records" + ("" if differences else ": nothing a ratio depends on"))
    for label, a, b in differences:
        print(f"  {label}: {a} | {b}")
    rows = compare(run, reference)
    if not rows:
        die(f"no chapter measured in both runs with {BASELINE} beside it: nothing to compare")
    print_table(rows, compared(run))
    marked = [r for r in rows if r[4]]
    print(f"\n{len(marked)} of {len(rows)} speedups differ by more than the runs' spread"
          + (": look at what differs in the records above" if marked and differences else ""))
    for chapter, phase, a, b, _ in marked:
        print(f"differs: {chapter} {phase}: {a[0]:.2f} [{a[1]:.2f}-{a[2]:.2f}] here, "
              f"{b[0]:.2f} [{b[1]:.2f}-{b[2]:.2f}] in the reference")
    out = args.out or paths[0].parent
    out.mkdir(parents=True, exist_ok=True)
    plot(rows, compared(run), differences, "this run", "the reference", out / "compare.png")
    print(f"wrote {out / 'compare.png'}")
    return 0
