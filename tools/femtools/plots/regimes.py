"""The regime sweep's plot (results/regimes.png, `fem-tools runs regimes`): the overall step's
speedup over chapter 01, the solve table's two poster ratios and where chapter 01's step goes,
each against chapter 01's CG iterations (the stiffer, the more)."""
import matplotlib.pyplot as plt
from matplotlib.lines import Line2D
from matplotlib.ticker import FuncFormatter

from femtools.files import replacing
from femtools.results import poster
from femtools.results.common import BASELINE, footer
from femtools.results.phases import label
from femtools.results.regimes import (SHARE_PHASES, body_points, chapter_names, iterations, share,
                                      solver_ratio, speedup)

BODY_STYLES = [("-", "o"), ("--", "s"), (":", "^"), ("-.", "D")]
# The solve table's two ratios the poster reports: colour, what the solver is.
SOLVER_LINES = {"eigen_cg_guess": ("tab:orange", "Eigen solveWithGuess()"), "pcg_ch06": ("tab:purple", "ours")}
SHARES = SHARE_PHASES + ["other"]


def chapter_colours(names):
    cmap = plt.get_cmap("tab10" if len(names) <= 10 else "tab20")
    return {n: cmap(i % cmap.N) for i, n in enumerate(names)}


def poster_line(ax, key, colour="black"):
    target = poster.number(key)
    ax.axhline(target, color=colour, lw=1.2 if key == "step" else 1.0, ls=(0, (6, 3)))
    ax.annotate(f"poster x{target:g}", (0.01, target), xycoords=("axes fraction", "data"),
                va="bottom", fontsize=8, **({} if key == "step" else {"color": colour}))


def draw_lines(data, axes, colours, styles, have_solvers):
    """Every body's lines on the three panels."""
    ax_step, ax_share = axes[0], axes[-1]
    for body in data["bodies"]:
        pts = body_points(data, body)
        xs = [iterations(p) for p in pts]
        line, marker = styles[body]
        for n in colours:
            if n != BASELINE:
                ax_step.plot(xs, [speedup(p, n) for p in pts], line, marker=marker, ms=4, color=colours[n])
        for i, phase in enumerate(SHARES):
            ax_share.plot(xs, [100 * share(p, phase) for p in pts], line, marker=marker, ms=4,
                          color=plt.get_cmap("Dark2")(i))
        if have_solvers:
            for key, (colour, _) in SOLVER_LINES.items():
                axes[1].plot(xs, [solver_ratio(p, key) for p in pts], line, marker=marker, ms=4, color=colour)


def label_step(ax, colours, body_handles):
    poster_line(ax, "step")
    ax.axhline(1.0, color="0.5", lw=0.7)
    ax.set_yscale("log")
    ax.set_ylabel(f"overall step speedup over {BASELINE} (median ratio, log)")
    ax.set_title("Overall step: speedup over chapter 01")
    chapter_handles = [Line2D([], [], color=colours[n], label=n) for n in colours if n != BASELINE]
    ax.legend(handles=chapter_handles + body_handles, fontsize=7, ncol=2)


def label_solvers(ax, body_handles):
    for key, (colour, _) in SOLVER_LINES.items():
        poster_line(ax, key, colour)
    ax.axhline(1.0, color="0.5", lw=0.7)
    ax.set_yscale("log")
    ax.set_ylabel("Eigen solve() time over the solver's (median ratio, log)")
    ax.set_title("The solve table: the same systems, the same tolerance")
    ax.legend(handles=[Line2D([], [], color=c, label=f"{key} ({what})")
                       for key, (c, what) in SOLVER_LINES.items()] + body_handles, fontsize=7)


def label_shares(ax, body_handles):
    ax.set_ylabel("share of chapter 01's median step [%]")
    ax.set_ylim(0, 100)
    ax.set_title("Where chapter 01's step goes (Amdahl: what is left to gain)")
    ax.legend(handles=[Line2D([], [], color=plt.get_cmap("Dark2")(i),
                              label=label(ph) if ph != "other" else "other (update, copies)")
                       for i, ph in enumerate(SHARES)] + body_handles, fontsize=7)


def format_axes(axes):
    for ax in axes[:-1]:  # ratios on a log scale, labelled as plain ratios
        ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"x{v:g}"))
        ax.yaxis.set_minor_formatter(FuncFormatter(lambda v, _: f"x{v:g}" if str(v)[0] in "235" else ""))
    for ax in axes:
        ax.set_xscale("log")
        ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
        ax.xaxis.set_minor_formatter(FuncFormatter(lambda v, _: f"{v:g}" if str(v)[0] in "25" else ""))
        ax.set_xlabel("chapter 01's CG iterations per step (median, log)")
        ax.grid(which="both", alpha=0.3)


def plot(data, path):
    colours = chapter_colours(chapter_names(data))
    styles = {b: BODY_STYLES[i % len(BODY_STYLES)] for i, b in enumerate(data["bodies"])}
    have_solvers = all(p.get("solvers") for p in data["points"])
    fig, axes = plt.subplots(1, 3 if have_solvers else 2, figsize=(18 if have_solvers else 13, 5.8))
    draw_lines(data, axes, colours, styles, have_solvers)
    body_handles = [Line2D([], [], color="0.3", ls=styles[b][0], marker=styles[b][1], label=b)
                    for b in data["bodies"]]
    label_step(axes[0], colours, body_handles)
    if have_solvers:
        label_solvers(axes[1], body_handles)
    label_shares(axes[-1], body_handles)
    format_axes(axes)
    e = data["E_values"]
    fig.suptitle(f"Regimes: Young's modulus E from {min(e):g} to {max(e):g} Pa at dt = {data['dt']:g} s; "
                 "the stiffer, the more CG iterations", fontsize=10)
    head = dict(data, mesh=None, steps=data["steps"])
    fig.text(0.01, 0.005, f"{', '.join(data['bodies'])}, {data['steps']} steps per point | " + footer(head),
             fontsize=6.5, color="0.35", ha="left", va="bottom", wrap=True)
    fig.tight_layout(rect=(0, 0.04, 1, 0.97))
    path.parent.mkdir(parents=True, exist_ok=True)
    with replacing(path) as tmp:
        fig.savefig(tmp, dpi=120)
    plt.close(fig)
    print(f"wrote {path}")
