"""Chapter 12's figures: padded_lanes.png and soa_batch.png, schematics of the code's layouts,
their sizes read from chapter 12's sources (`fem-tools plots figures lanes`)."""
import re

import matplotlib
import matplotlib.pyplot as plt
from matplotlib.patches import Rectangle

from femtools.paths import ROOT
from femtools.plots.style import finish_figure as finish
from femtools.results.common import ResultsError

CHAPTER12 = ROOT / "chapters" / "12_half_the_bytes"


def constant(pattern, what):
    """The first match of pattern in chapter 12's sources, as ints; a clear error without one."""
    for path in sorted(CHAPTER12.glob("*.[hc]pp")):
        m = re.search(pattern, path.read_text())
        if m:
            return [int(g) for g in m.groups()]
    raise ResultsError(f"no {what} in {CHAPTER12.relative_to(ROOT)}/*.hpp|cpp (pattern {pattern!r}): "
                       "update fem-tools plots figures to the code")


def cell(ax, x, y, text, color, w=1.0, h=1.0, hatch=None, fontsize=7.5):
    ax.add_patch(Rectangle((x, y), w, h, fc=color, ec="0.3", lw=0.8, hatch=hatch))
    ax.text(x + w / 2, y + h / 2, text, ha="center", va="center", fontsize=fontsize)


def draw_padded_block(ax, rows, lanes, y0, title):
    """A float block of rows x rows, column-major, then the next block's first floats; below,
    the load of each column as `lanes` floats and its multiply-add with x_j."""
    colours = ["#cfe2f3", "#d9ead3", "#fce5cd", "#ead1dc", "#fff2cc", "#d0e0e3"]
    total = rows * rows + lanes - rows
    ax.text(-0.3, y0 + 0.5, "memory\n(floats)", ha="right", va="center", fontsize=8)
    for k in range(total):
        if k < rows * rows:
            cell(ax, k, y0, f"a{k % rows}{k // rows}", colours[(k // rows) % len(colours)])
        else:
            cell(ax, k, y0, f"n{k - rows * rows}", "0.85", hatch="//")
    ax.text(rows * rows + (lanes - rows) / 2, y0 + 1.25, "next block\n(or the padding block)",
            ha="center", va="bottom", fontsize=7)
    for j in range(rows):
        y = y0 - 1.6 * (j + 1)
        for l in range(lanes):
            k = rows * j + l
            extra = l >= rows
            name = f"a{l}{j}" if not extra else (f"a{k % rows}{k // rows}" if k < rows * rows
                                                 else f"n{k - rows * rows}")
            cell(ax, k, y, name, "0.85" if extra else colours[j % len(colours)],
                 hatch="//" if extra else None)
        ax.text(rows * j + lanes + 0.3, y + 0.5,
                f"x x_{j}  ->  sum_{j}   (lanes {rows}-{lanes - 1}: dropped)" if lanes > rows + 1
                else f"x x_{j}  ->  sum_{j}   (lane {rows}: dropped)", va="center", fontsize=8)
        ax.text(-0.3, y + 0.5, f"column {j}:\n{lanes} lanes", ha="right", va="center", fontsize=8)
    ax.text(-3.2, y0 + 2.3, title, fontsize=9, fontweight="bold", va="bottom")


def plot_padded_lanes(out):
    fine, coarse = constant(r"R == 3 \? (\d+) : (\d+)",
                            "kPaddedColumn<R> (the padded column's floats)")
    fig, ax = plt.subplots(figsize=(16, 7.6))
    y0 = 0.0
    for rows, lanes in ((3, fine), (6, coarse)):
        where = "the finest level's 3x3 blocks" if rows == 3 else "the coarse levels' 6x6 blocks"
        draw_padded_block(ax, rows, lanes, y0, f"{where}: a column of {rows} floats loaded as "
                          f"{lanes} lanes, one vector multiply-add")
        y0 -= 1.6 * rows + 4.2
    ax.set_xlim(-3.4, 36 + coarse + 11)
    ax.set_ylim(y0 + 3.6, 3.8)
    ax.set_aspect("equal")
    ax.set_axis_off()
    fig.suptitle("Chapter 12's float V-cycle: each block column read in padded lanes (add_product "
                 "in reduced_kernels.hpp)", fontsize=11)
    finish(fig, out / "padded_lanes.png",
           "aIJ: row I, column J of the block, stored column by column; grey: floats "
           "past the column, whose products land in lanes that total() drops. The sums of the "
           "columns add up at the end. Lane counts read from chapter 12's kPaddedColumn<R>. Without the "
           "padding, Eigen 3.4 keeps a Matrix<float, 3, 1> in scalars (its packet of 4 floats is longer than the "
           "column): three scalar multiply-adds per column.", top=0.97)


def registers(size, width):
    count = -(-size // width)
    return f"{count} register" + ("s" if count > 1 else "") + f" of {width} bytes"


def plot_soa_batch(out):
    lanes, = constant(r"constexpr int kLanes = (\d+);", "kLanes (elements per batch)")
    align, = constant(r"struct alignas\((\d+)\) Lanes", "the alignment of Lanes")
    fig, (left, right) = plt.subplots(1, 2, figsize=(14, 6.6), gridspec_kw={"width_ratios": [1, 1.25]})
    colours = matplotlib.colormaps["Pastel1"].colors
    # Left: element by element, each element's F a 3x3 matrix of its own (chapter 08).
    for e in range(lanes):
        for k in range(9):
            cell(left, k, lanes - 1 - e, f"F{k % 3}{k // 3}", colours[e % len(colours)], fontsize=6.5)
        left.text(-0.3, lanes - 0.5 - e, f"element {e}", ha="right", va="center", fontsize=8)
    left.set_title("chapter 08: one element at a time\n(its F a Matrix3d: 9 doubles, column by "
                   "column;\na column of 3 fills at most part of a vector register)", fontsize=9)
    left.set_xlim(-3, 9.2)
    # Right: structure of arrays, one Lanes per entry, the elements across the lanes.
    for k in range(9):
        for e in range(lanes):
            cell(right, e, 8 - k, f"e{e}", colours[e % len(colours)], fontsize=6.5)
        right.text(-0.3, 8.5 - k, f"F[{k}] = F({k // 3},{k % 3})", ha="right", va="center", fontsize=8)
    right.add_patch(Rectangle((-0.08, 7.92), lanes + 0.16, 1.16, fill=False, ec="firebrick", lw=2))
    right.text(lanes + 0.3, 8.5, f"one Lanes: {lanes} doubles,\n{8 * lanes} bytes (alignas({align})):\n"
               f"{registers(8 * lanes, 64)} AVX-512\nor {registers(8 * lanes, 32)} AVX2",
               va="center", fontsize=8, color="firebrick")
    right.add_patch(Rectangle((2.92, -0.08), 1.16, 9.16, fill=False, ec="navy", lw=2, ls="--"))
    right.text(3.5, -0.5, "lane 3: element first + 3\n(its F read down the column)", ha="center",
               va="top", fontsize=8, color="navy")
    right.set_title(f"chapter 12: a batch of {lanes} elements, structure of arrays\n(F[3i+j].v[l] "
                    "in element_batch.cpp: one loop over the lanes per entry,\nevery lane busy: "
                    "F(i,j) = sum_k Ds(i,k) Dm^-1(k,j) for all at once)", fontsize=9)
    right.set_xlim(-3.2, lanes + 5.0)
    for ax in (left, right):
        ax.set_ylim(-1.6, 9.3)
        ax.set_aspect("equal")
        ax.set_axis_off()
    fig.suptitle("The element pass's numbers in memory: array of structures against structure of "
                 "arrays", fontsize=11)
    finish(fig, out / "soa_batch.png",
           f"kLanes = {lanes} and alignas({align}) read from element_batch.hpp. A batch "
           f"shorter than {lanes} repeats its last element in the remaining lanes (valid numbers, "
           "results not written).", top=0.95)
