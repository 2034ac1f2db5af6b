"""What the plots share: the footer and the check of a drawn figure's layout (bench plots), the
finish of the figures, a chapter's bar style, and the palette."""
import textwrap

import matplotlib
import matplotlib.pyplot as plt

from femtools.files import replacing
from femtools.results.common import ResultsError, chapter_color, footer

# Distinct colours for neighbouring aggregates (a greedy colouring needs only a few).
PALETTE = list(matplotlib.colormaps["tab10"].colors) + list(matplotlib.colormaps["Set2"].colors)


def finish(fig, data, path):
    text = footer(data)
    busy = "BUSY MACHINE" in text
    fig.text(0.01, 0.005, text, fontsize=6.5, color="firebrick" if busy else "0.35", ha="left",
             va="bottom", wrap=True)
    fig.tight_layout(rect=(0, 0.08 if busy else 0.05, 1, 1))
    problems = layout_problems(fig)
    if problems:
        plt.close(fig)
        raise ResultsError(f"{path.name}: the layout hides what it shows: " + "; ".join(problems))
    with replacing(path) as tmp:
        fig.savefig(tmp, dpi=130)
    plt.close(fig)
    print(f"wrote {path}")


def layout_problems(fig):
    """What a reader could not read, found from the drawn figure: a legend box over a bar or
    a marker of its axes, and tick labels of one axis that run into each other."""
    renderer = fig.canvas.get_renderer()
    problems = []
    for ax in fig.axes:
        legend = ax.get_legend()
        if legend is not None:
            box = legend.get_window_extent(renderer)
            covered = [a for a in list(ax.patches) + list(ax.collections)
                       if a.get_visible() and a.get_window_extent(renderer).overlaps(box)
                       and a.get_window_extent(renderer).width > 0]
            if covered:
                problems.append(f"the legend of '{ax.get_title()}' covers {len(covered)} marks")
        for axis, name in ((ax.xaxis, "x"), (ax.yaxis, "y")):
            # Slanted labels (the allocation plot's) have boxes that overlap by design: their
            # text runs parallel, apart. Only level labels are checked.
            boxes = [t.get_window_extent(renderer) for t in axis.get_ticklabels(which="both")
                     if t.get_visible() and t.get_text() and t.get_rotation() == 0]
            if any(a.overlaps(b) for i, a in enumerate(boxes) for b in boxes[i + 1:]):
                problems.append(f"the {name} tick labels of '{ax.get_title()}' overlap")
    return problems


def style(c):
    """A row's bar style: its chapter's colour (a variant in the light shade of its original's),
    and a hatch for a row on more than one thread ("09_threads@2" beside "09_threads@1"), so that
    the rows of one chapter at several thread counts can be told apart."""
    threaded = c.get("threads", 1) > 1
    return {"color": chapter_color(c["chapter"], c.get("variant_of", "")),
            "hatch": "..." if threaded else None, "edgecolor": "white" if threaded else None,
            "linewidth": 0}


def legend_outside(ax, title=None):
    """The legend right of the axes, where it covers no bar (the poster's hatched bars
    included), one entry per row."""
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0,
              title=title, title_fontsize=8)


def mark_zero(ax, x, text="0"):
    """A phase at 0 ms (a chapter that does not have it: chapter 08's fused pass builds no
    df/dx) gets no bar on a log axis; a small mark at the bottom says that it is zero."""
    ax.annotate(text, (x, 0), xycoords=ax.get_xaxis_transform(), xytext=(0, 2),
                textcoords="offset points", ha="center", va="bottom", fontsize=6, color="0.3")


def finish_figure(fig, path, note, top=0.95, left=0.0):
    """The note on the figure's data at the bottom left, the layout, the file."""
    lines = textwrap.wrap(note, int(16 * fig.get_figwidth()))  # about 16 characters an inch
    fig.text(0.01, 0.008, "\n".join(lines), fontsize=7.5, color="0.35")
    fig.tight_layout(rect=(left, (0.1 + 0.14 * len(lines)) / fig.get_figheight(), 1, top))
    with replacing(path) as tmp:
        fig.savefig(tmp, dpi=130)
    plt.close(fig)
    print(f"wrote {path}")
