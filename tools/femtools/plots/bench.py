"""Plots the benchmark results: from results/bench.json only (no numbers typed here).

    fem-tools plots bench results/bench.json --out results     phases (grouped, stacked), speedup,
                                                            allocations, solvers
    fem-tools plots bench --scaling results/scaling.json --out results   scaling
    fem-tools plots bench --threads results/threads.json --out results   threads (thread scaling)
"""
import pathlib

import matplotlib.pyplot as plt
import numpy as np

from femtools.args import command_parser
from femtools.plots.style import finish, legend_outside, mark_zero, style
from femtools.results import poster
from femtools.results.common import BASELINE, ResultsError, chapter_color, chapter_dir, die, run_label
from femtools.results.phases import PHASE_LABELS, all_phases, colour, parts
from femtools.results.schema import load_checked


def ratio_ticks(ax):
    """A log axis of ratios labelled x0.5, x1, x2 (no "1.05 x 10^0"): minor ticks are labelled
    only when the axis spans less than a decade, where there are too few major ones."""
    from matplotlib.ticker import FuncFormatter, NullFormatter
    label = FuncFormatter(lambda v, _: f"x{v:.3g}")
    ax.yaxis.set_major_formatter(label)
    low, high = ax.get_ylim()
    ax.yaxis.set_minor_formatter(label if high / low < 10 else NullFormatter())


def chapter_labels(chapters):
    return [c["chapter"] for c in chapters]


def plot_phases(data, out):
    chapters = data["chapters"]
    phases = all_phases(data)
    x = np.arange(len(phases))
    width = 0.8 / len(chapters)
    fig, ax = plt.subplots(figsize=(12, 5))
    zeros = False
    for i, c in enumerate(chapters):
        med = np.array([c["median_ms"][p] for p in phases])
        lo = med - np.array([c["q1_ms"][p] for p in phases])
        hi = np.array([c["q3_ms"][p] for p in phases]) - med
        pos = x + (i - (len(chapters) - 1) / 2) * width
        shown = med > 0
        ax.bar(pos[shown], med[shown], width, yerr=[np.maximum(lo, 0)[shown], np.maximum(hi, 0)[shown]],
               capsize=2, label=c["chapter"], **style(c))
        for xp in pos[~shown]:
            mark_zero(ax, xp)
            zeros = True
    ax.set_yscale("log")
    ax.set_xticks(x, [PHASE_LABELS[p] for p in phases])
    ax.set_ylabel("median time per step [ms] (log; bars: quartiles)")
    ax.set_title(f"Time per phase of one step, chapter by chapter ({run_label(data)})")
    legend_outside(ax, "0: a phase at 0 ms, no bar" if zeros else None)
    ax.grid(axis="y", which="both", alpha=0.3)
    finish(fig, data, out / "phases.png")


def stacked_rows(data):
    """Per row of the run: (label, the phases' medians in the run's order and the rest, the step's
    median). "rest" is the step's median minus the phases' medians (the state update, the
    profiling itself, and the difference between a median of sums and a sum of medians),
    never drawn below 0."""
    rows = []
    for c in data["chapters"]:
        med = c["median_ms"]
        times = [med[p] for p in parts(data)]
        rows.append((c["chapter"], times + [max(med["step"] - sum(times), 0.0)], med["step"]))
    return rows


def plot_phases_stacked(data, out):
    """The course at a glance: one bar per row (chapter, and chapter@threads), the step split
    into its phases, with the step's median and its speedup over the first row at the end."""
    rows = stacked_rows(data)
    fig, ax = plt.subplots(figsize=(11, 0.36 * len(rows) + 2.2))
    y = np.arange(len(rows))
    left = np.zeros(len(rows))
    for k, phase in enumerate(parts(data) + ["rest"]):
        widths = np.array([r[1][k] for r in rows])
        label = PHASE_LABELS.get(phase, "rest of the step")
        if phase == "forces":
            label = "forces (from 08: the fused element pass)"
        ax.barh(y, widths, left=left, color=colour(phase) if phase != "rest" else "0.8", label=label,
                height=0.72)
        left += widths
    base = rows[0][2]
    for yi, (_, _, step) in zip(y, rows):
        ax.annotate(f"{step:.1f} ms" + (f"  x{base / step:.1f}" if yi > 0 else ""), (step, yi),
                    xytext=(4, 0), textcoords="offset points", va="center", fontsize=8)
    ax.set_yticks(y, [r[0] for r in rows], fontsize=9)
    ax.invert_yaxis()
    ax.set_xlim(0, 1.15 * max(r[2] for r in rows))
    ax.set_xlabel(f"median time per step [ms]; at the end: the step and its speedup over {rows[0][0]}")
    ax.set_title(f"The course at a glance: the step split into its phases ({run_label(data)})")
    # Beside the axes: inside them, a run with few rows (a variant's) has no free corner.
    legend_outside(ax, "phase (median per step)")
    ax.grid(axis="x", alpha=0.3)
    finish(fig, data, out / "phases_stacked.png")


def speedup_references(data):
    """Which row each bar of speedup.png compares with, and what the plot then shows:
    (pairs of (row, reference row), y-axis label, title). Chapter 01 when the run has it (the
    poster's comparison); without it, a variant over its original at the same thread count
    (`--chapters 10,10_mine`, the documented form of a variant's run); otherwise the first row."""
    chapters = data["chapters"]
    base = next((c for c in chapters if c["chapter"] == BASELINE), None)
    if base is not None:
        return ([(c, base) for c in chapters if c is not base], f"speedup over {BASELINE}",
                "Speedup per phase over the naive stepper")
    pairs = []
    for c in chapters:
        original = c.get("variant_of")
        ref = next((r for r in chapters if original and chapter_dir(r["chapter"]) == original
                    and r.get("threads", 1) == c.get("threads", 1)), None)
        if ref is not None:
            pairs.append((c, ref))
    if pairs:
        return pairs, "speedup over its original", "Speedup per phase of each variant over its original"
    first = chapters[0]
    return ([(c, first) for c in chapters[1:]], f"speedup over {first['chapter']}",
            f"Speedup per phase over {first['chapter']}")


def plot_speedup(data, out):
    pairs, ylabel, title = speedup_references(data)
    fig, ax = plt.subplots(figsize=(12, 5))
    if not pairs:
        ax.text(0.5, 0.5, "only one chapter measured: no speedup to show", ha="center", va="center")
        ax.set_axis_off()
        ax.set_title(f"Speedup ({run_label(data)})")
        finish(fig, data, out / "speedup.png")
        return
    # forces too: the same code up to chapter 07 (about x1), chapter 08's fused element pass after
    phases = all_phases(data)
    beside = poster.comparable(data) and pairs[0][1]["chapter"] == BASELINE
    bars = len(pairs) + (1 if beside else 0)
    x = np.arange(len(phases))
    width = 0.8 / bars
    several = len({ref["chapter"] for _, ref in pairs}) > 1
    for i, (c, ref) in enumerate(pairs):
        # A phase a chapter no longer has (chapter 08's df/dx, fused into its element pass) gets
        # no bar rather than an infinite one.
        s = [ref["median_ms"][p] / c["median_ms"][p] if c["median_ms"][p] > 0 else np.nan
             for p in phases]
        pos = x + (i - (bars - 1) / 2) * width
        label = c["chapter"] + (f" / {ref['chapter']}" if several else "")
        ax.bar(pos, s, width, label=label, **style(c))
        for xp, v in zip(pos, s):
            if np.isnan(v):
                mark_zero(ax, xp, "-")
    if beside:
        ax.bar(x + (len(pairs) - (bars - 1) / 2) * width,
               [poster.SPEEDUPS.get(p, np.nan) for p in phases], width, color="none",
               edgecolor="black", hatch="//", label="poster (optimized vs naive)")
    ax.axhline(1.0, color="0.3", lw=0.8)
    ax.set_yscale("log")
    # Two lines a label: the legend beside the axes narrows them, and a variant's long names
    # widen the legend.
    ax.set_xticks(x, [PHASE_LABELS[p].replace(" ", "\n", 1) for p in phases])
    ratio_ticks(ax)
    ax.set_ylabel(f"{ylabel} (median ratio, log)")
    ax.set_title(title + (", beside the poster's" if beside else "") + f" ({run_label(data)})")
    legend_outside(ax, "-: a phase at 0 ms, no ratio")
    ax.grid(axis="y", which="both", alpha=0.3)
    finish(fig, data, out / "speedup.png")


def plot_allocations(data, out):
    chapters = data["chapters"]
    counts = [c["allocations_per_step"] for c in chapters]
    fig, ax = plt.subplots(figsize=(max(9, 0.75 * len(chapters) + 3), 5))
    bars = ax.bar(chapter_labels(chapters), [max(a, 0.5) for a in counts],
                  **{k: [style(c)[k] for c in chapters] for k in ("color",)})
    for bar, c in zip(bars, chapters):
        if style(c)["hatch"]:
            bar.set_hatch(style(c)["hatch"])
            bar.set_edgecolor("white")
    for bar, a in zip(bars, counts):
        ax.annotate(f"{a:g}", (bar.get_x() + bar.get_width() / 2, bar.get_height()),
                    ha="center", va="bottom", fontsize=9)
    ax.set_yscale("log")
    ax.set_ylim(0.3, max(counts + [1]) * 3)
    ax.set_ylabel("heap allocations per step (log; 0 drawn at 0.5)")
    warmup = data.get("warmup_steps", 1)
    ax.set_title("Heap allocations per step, " + ("after the first" if warmup >= 1 else
                                                  "the first step included (no warm-up)")
                 + f" ({run_label(data)})")
    # Long names, variants among them: slanted, right-aligned under their bars, never overlapping.
    plt.setp(ax.get_xticklabels(), rotation=35, ha="right", rotation_mode="anchor", fontsize=8)
    finish(fig, data, out / "allocations.png")


def plot_solvers(data, out):
    solvers = data.get("solvers")
    if not solvers:
        # A run folder holds one run's files: a solve table of an earlier run must not stay
        # beside a JSON that has none.
        stale = out / "solvers.png"
        if stale.exists():
            stale.unlink()
            print(f"removed {stale}: this run has no solve table (--no-solvers)")
        return
    names = [s["name"] for s in solvers]
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(12, 4.8))
    if all("setup_ms" in s and "solve_ms" in s for s in solvers):
        setup = [s["setup_ms"] for s in solvers]
        ax1.barh(names, setup, color="tab:orange", label="setup: compute() / factorize()")
        ax1.barh(names, [s["solve_ms"] for s in solvers], left=setup, color="tab:blue",
                 label="solve")
    else:
        ax1.barh(names, [s["median_ms"] for s in solvers], color="tab:blue", label="measured")
    if poster.comparable(data):  # absolute times compare only on the poster's run
        reported = [poster.SOLVE_MS.get(n) for n in names]
        ys = [i for i, p in enumerate(reported) if p is not None]
        ax1.scatter([reported[i] for i in ys], ys, marker="D", color="black", zorder=3,
                    clip_on=False, label="poster")
    # A log axis: the solvers span two decades, and the poster's few milliseconds would sit
    # squashed against zero on a linear one. The legend below the axes covers no bar.
    ax1.set_xscale("log")
    values = [v for s in solvers for v in (s.get("setup_ms", 0), s.get("solve_ms", 0),
                                           s.get("median_ms", 0)) if v > 0]
    if values:  # a bar from 0 (no set-up) would stretch a log axis down to its smallest tick
        ax1.set_xlim(max(min(values) / 2, max(values) / 1e4), max(values) * 2)
    ax1.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.2), ncol=3, frameon=False)
    ax1.invert_yaxis()
    ax1.set_xlabel("median time per solve [ms, log]")
    ax1.set_title("Time per solve")
    ax2.barh(names, [s["iterations"] for s in solvers], color="tab:green")
    ax2.invert_yaxis()
    ax2.set_xlabel("CG iterations per solve (median; 0 for a direct solver)")
    ax2.set_title("Iterations")
    fig.suptitle(f"The solve table: the same systems, the same tolerance ({run_label(data)})")
    finish(fig, data, out / "solvers.png")


def spread_labels(ends, min_gap):
    """Moves label heights (log10) apart by at least min_gap, keeping their order."""
    ends = sorted(ends, key=lambda e: e[1])
    placed = []
    for x, y, label, color in ends:
        ly = np.log10(y)
        if placed and ly - placed[-1][1] < min_gap:
            ly = placed[-1][1] + min_gap
        placed.append((x, ly, y, label, color))
    # Centre the stack on the line ends, so that it does not climb out of the axes.
    shift = np.mean([np.log10(e[1]) for e in ends]) - np.mean([p[1] for p in placed])
    return [(x, ly + shift, y, label, color) for x, ly, y, label, color in placed]


def plot_scaling(data, out):
    runs = data["runs"]
    fig, axes = plt.subplots(1, 2, figsize=(13, 5.2))
    chapters = sorted({r["chapter"] for r in runs})
    stopped = {s["chapter"] for s in data.get("skipped", [])}
    for key, ax, title in (("step_ms", axes[0], "overall step"), ("solve_ms", axes[1], "solve")):
        ends = []
        for c in chapters:
            pts = sorted((r["nodes"], r[key]) for r in runs if r["chapter"] == c)
            xs, ys = zip(*pts)
            line, = ax.plot(xs, ys, marker="o", ms=3, color=chapter_color(c))
            if c in stopped:
                ax.scatter([xs[-1]], [ys[-1]], marker="x", s=70, color=line.get_color(), zorder=3)
            ends.append((xs[-1], ys[-1], c + (" (stopped)" if c in stopped else ""), line.get_color()))
        ax.set_xscale("log")
        ax.set_yscale("log")
        lo, hi = ax.get_ylim()
        column = 1.5 * max(e[0] for e in ends)  # all labels in one column, right of the lines
        for x, ly, y, label, color in spread_labels(ends, 0.05 * np.log10(hi / lo)):
            ax.annotate(label, (x, y), xytext=(column, 10 ** ly), fontsize=7, color=color,
                        va="center", arrowprops=dict(arrowstyle="-", color=color, lw=0.5))
        ax.set_xlim(right=column * 8)
        ax.set_xlabel("nodes (log)")
        ax.set_ylabel(f"median {title} time per step [ms] (log)")
        ax.set_title(f"{title.capitalize()} against mesh size")
        ax.grid(which="both", alpha=0.3)
    fig.suptitle(f"Scaling over the beam series, {data['scene']} scene (x: the next size went over the "
                 f"{data.get('budget_seconds', '?')} s budget per run)", fontsize=10)
    finish(fig, data, out / "scaling.png")


def plot_threads(data, out):
    """Step and solve time of the threaded chapters (rows NAME@N) against N, with the ideal
    line t(1) / N and the chapter before them (one thread) as a horizontal reference."""
    threaded = [c for c in data["chapters"] if "@" in c["chapter"]]
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.8))
    if not threaded:
        for ax in axes:
            ax.text(0.5, 0.5, "no threaded chapter (NAME@N) in the results", ha="center", va="center")
            ax.set_axis_off()
        finish(fig, data, out / "threads.png")
        return
    counts = sorted({c["threads"] for c in threaded})
    for key, ax, title in (("step", axes[0], "overall step"), ("solve", axes[1], "solve")):
        for name in sorted({chapter_dir(c["chapter"]) for c in threaded}):
            rows = sorted((c for c in threaded if chapter_dir(c["chapter"]) == name),
                          key=lambda c: c["threads"])
            xs = [c["threads"] for c in rows]
            ys = [c["median_ms"][key] for c in rows]
            lo = [c["median_ms"][key] - c["q1_ms"][key] for c in rows]
            hi = [c["q3_ms"][key] - c["median_ms"][key] for c in rows]
            line = ax.errorbar(xs, ys, yerr=[np.maximum(lo, 0), np.maximum(hi, 0)], marker="o",
                               capsize=3, label=f"{name} (median, quartiles)")
            one = next((c["median_ms"][key] for c in rows if c["threads"] == 1), None)
            if one is not None:
                ax.plot(counts, [one / n for n in counts], ls="--", color=line[0].get_color(),
                        alpha=0.6, label=f"{name} ideal: t(1) / threads")
            for x, y in zip(xs, ys):
                if one is not None:
                    ax.annotate(f"x{one / y:.2f}", (x, y), textcoords="offset points", xytext=(6, 6),
                                fontsize=8)
        # The single-threaded chapter just before the first threaded one: what threads add to.
        first = data["chapters"].index(threaded[0])
        if first > 0:
            ref = data["chapters"][first - 1]
            ax.axhline(ref["median_ms"][key], color="0.5", lw=0.8, ls=":")
            ax.annotate(f"{ref['chapter']} (one thread)", (counts[-1], ref["median_ms"][key]),
                        fontsize=8, color="0.35", va="bottom", ha="right")
        ax.set_xticks(counts)
        ax.set_xlabel("threads")
        ax.set_ylabel(f"median {title} time per step [ms]")
        ax.set_ylim(bottom=0)
        ax.set_title(f"{title.capitalize()} against threads")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle(f"Thread scaling on a machine with {data['machine'].get('threads', '?')} hardware threads",
                 fontsize=10)
    finish(fig, data, out / "threads.png")


def main(argv=None, prog=None):
    parser = command_parser(prog, __doc__)
    parser.add_argument("bench", nargs="?", help="results/bench.json")
    parser.add_argument("--scaling", help="results/scaling.json")
    parser.add_argument("--threads", help="results/threads.json (fem_bench --threads 1,2,...)")
    parser.add_argument("--out", default="results", help="directory for the PNG files")
    args = parser.parse_args(argv)
    if not args.bench and not args.scaling and not args.threads:
        parser.error("give a bench.json, or --scaling scaling.json, or --threads threads.json")
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    try:
        if args.bench:
            data = load_checked(args.bench)
            print(f"plots of {args.bench}: {run_label(data)}, "
                  f"{', '.join(c['chapter'] for c in data['chapters'])}")
            plot_phases(data, out)
            plot_phases_stacked(data, out)
            plot_speedup(data, out)
            plot_allocations(data, out)
            plot_solvers(data, out)
        if args.scaling:
            plot_scaling(load_checked(args.scaling, scaling=True), out)
        if args.threads:
            plot_threads(load_checked(args.threads), out)
    except ResultsError as e:
        die(f"fem-tools plots bench: {e}")
