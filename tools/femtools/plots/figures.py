"""The figures a table cannot show, each drawn from the code's own data (no number typed here):

    figures.py --out docs/images              every figure below
    figures.py hierarchy --out docs/images    chapter 10: vcycle.png and aggregates.png, from
                                              docs/data/figures/hierarchy.json (fem_figure_data)
    figures.py node-orders --out docs/images  chapter 11: node_orders.png, the matrix pattern in
                                              the file's, RCM and Morton orders, from
                                              docs/data/figures/node-orders.json (fem_figure_data)
    figures.py lanes --out docs/images        chapter 12: padded_lanes.png and soa_batch.png,
                                              schematics of the code's layouts, their sizes read
                                              from chapter 12's sources

The meshes are read here with gmsh's Python API and numbered as common/mesh.cpp numbers them
(nodes by tag, unused nodes dropped); the JSON's tet checksum says whether that numbering is
the code's. `./tutorial.sh lessons` writes the JSON, `./tutorial.sh docs` draws the figures.
"""
import pathlib

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.collections import LineCollection, PolyCollection
from matplotlib.patches import FancyArrowPatch, Rectangle

from femtools.args import command_parser
from femtools.plots.lanes import plot_padded_lanes, plot_soa_batch
from femtools.plots.style import PALETTE, finish_figure as finish
from femtools.paths import ROOT
from femtools.results.common import ResultsError, die, load

DATA = ROOT / "docs" / "data" / "figures"
# ---- the mesh, numbered as the code numbers it -------------------------------------------------

def load_mesh(record):
    """(X: N x 3, tets: T x 4) of the record's mesh, numbered as fem::load_mesh numbers it;
    raises ResultsError when the record's counts or tet checksum disagree."""
    import gmsh
    path = ROOT / record["mesh"]
    gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Verbosity", 1)
        gmsh.open(str(path))
        tags, coords, _ = gmsh.model.mesh.getNodes(-1, -1, False, False)
        _, corners = gmsh.model.mesh.getElementsByType(4)
    finally:
        gmsh.finalize()
    order = np.argsort(tags)  # node i: the i-th smallest tag
    index_of_tag = {int(t): i for i, t in enumerate(np.asarray(tags)[order])}
    X = np.asarray(coords).reshape(-1, 3)[order]
    tets = np.array([index_of_tag[int(t)] for t in corners]).reshape(-1, 4)
    used = np.unique(tets)  # unused nodes dropped, the rest keep their order
    new = np.full(len(X), -1)
    new[used] = np.arange(len(used))
    X, tets = X[used], new[tets]
    checksum = int(np.sum(np.arange(len(tets), dtype=np.int64) * tets.sum(axis=1)))
    if (len(X), len(tets), checksum) != (record["nodes"], record["tets"], record["tet_checksum"]):
        raise ResultsError(f"{record['mesh']} is not numbered here as fem_figure_data numbered it "
                           f"({len(X)} nodes, {len(tets)} tets, checksum {checksum} against "
                           f"{record['nodes']}, {record['tets']}, {record['tet_checksum']}): "
                           "rerun ./tutorial.sh lessons")
    return X, tets


def node_pairs(tets):
    """The coupled node pairs (i, j), both ways and the diagonal: the block pattern of A."""
    i = np.repeat(tets, 4, axis=1).ravel()
    j = np.tile(tets, (1, 4)).ravel()
    pairs = np.unique(np.stack([i, j], axis=1), axis=0)
    return pairs[:, 0], pairs[:, 1]


# ---- chapter 10: the V-cycle and the aggregates -------------------------------------------------

def level_text(level, index):
    nodes = level["dofs"] // level["block"]
    what = "mesh nodes" if index == 0 else "aggregates"
    return (f"level {index}: {level['dofs']} unknowns\n({nodes} {what} x {level['block']}), "
            f"{level['blocks']} stored\n{level['block']}x{level['block']} blocks, "
            f"{level['parts']} row block{'s' if level['parts'] > 1 else ''}")


def box(ax, x, y, text, color):
    ax.text(x, y, text, ha="center", va="center", fontsize=8,
            bbox=dict(boxstyle="round,pad=0.4", fc=color, ec="0.3", lw=0.8))


def arrow(ax, start, end, text, side):
    ax.add_patch(FancyArrowPatch(start, end, arrowstyle="-|>", mutation_scale=14, color="0.25",
                                 lw=1.2, shrinkA=28, shrinkB=28))
    mid = ((start[0] + end[0]) / 2, (start[1] + end[1]) / 2)
    ax.annotate(text, mid, xytext=(side * 10, 0), textcoords="offset points", fontsize=8,
                ha="left" if side > 0 else "right", va="center", color="0.2")


def plot_vcycle(h, out):
    """One V-cycle of chapter 10 as Multigrid::cycle runs it, on the hierarchy's real levels."""
    levels = h["levels"]
    n = len(levels)
    steps = h["smoothing_steps"]
    fig, ax = plt.subplots(figsize=(12, 1.5 * n + 1.0))
    xs = np.linspace(3.7, 10.1, 2 * n - 1)  # down the left arm, the coarsest at the bottom, up
    for k in range(n):
        y = n - 1 - k
        ax.text(0.05, y, level_text(levels[k], k), va="center", fontsize=8.5)
        ax.axhline(y, xmin=0.3, color="0.9", lw=6, zorder=0)
        if k == n - 1:
            box(ax, xs[k], y, f"coarsest: dense Cholesky\nsolve ({levels[k]['dofs']} unknowns)",
                "#f4d6a0")
            continue
        box(ax, xs[k], y, f"pre-smoothing: {h['smoother']},\n{steps} steps from zero;\n"
                          "residual r = b - A x", "#cfe2f3")
        box(ax, xs[2 * n - 2 - k], y, f"correction x += P x_c;\npost-smoothing:\n"
                                      f"{h['smoother']}, {steps} steps", "#d9ead3")
        arrow(ax, (xs[k], y), (xs[k + 1], y - 1), "restriction\nb_c = P^T r", -1)
        arrow(ax, (xs[2 * n - 3 - k], y - 1), (xs[2 * n - 2 - k], y), "prolongation\nP x_c", 1)
    ax.set_xlim(0, 11.0)
    ax.set_ylim(-0.45, n - 0.55)
    ax.set_axis_off()
    ax.set_title(f"One V-cycle of chapter 10 on {pathlib.Path(h['mesh']).name} ({h['scene']} "
                 "scene): the preconditioner of every PCG iteration", fontsize=10)
    finish(fig, out / "vcycle.png",
           "Levels and sizes: the hierarchy as chapter 10's stepper sets it up "
           "(fem_figure_data hierarchy, docs/data/figures/hierarchy.json); P: the smoothed "
           "prolongator from a level to the one below.", top=1)


def colour_aggregates(aggregate, pairs):
    """A colour index per aggregate, different for aggregates that share a mesh edge (greedy,
    most-connected first)."""
    count = max(aggregate) + 1
    agg = np.asarray(aggregate)
    a, b = agg[pairs[0]], agg[pairs[1]]
    neighbours = [set() for _ in range(count)]
    for p, q in zip(a[a != b], b[a != b]):
        neighbours[p].add(q)
    colour = np.full(count, -1)
    for c in sorted(range(count), key=lambda c: -len(neighbours[c])):
        taken = {colour[d] for d in neighbours[c]}
        colour[c] = next(k for k in range(len(PALETTE)) if k not in taken)
    return colour


def top_face(X, tets):
    """The triangles of the boundary on the top face (z at its maximum)."""
    faces = np.sort(np.concatenate([tets[:, [0, 1, 2]], tets[:, [0, 1, 3]], tets[:, [0, 2, 3]],
                                    tets[:, [1, 2, 3]]]), axis=1)
    unique, counts = np.unique(faces, axis=0, return_counts=True)
    boundary = unique[counts == 1]
    top = np.isclose(X[:, 2], X[:, 2].max(), atol=1e-9 * np.ptp(X))
    return boundary[top[boundary].all(axis=1)]


def draw_aggregates(ax, X, triangles, node_aggregate, colour):
    """Each top-face node's median-dual cell (its corners of the triangles around it, cut at the
    edge midpoints and centroids) in its aggregate's colour, the borders between aggregates black."""
    cells, colours, borders = [], [], []
    for t in triangles:
        p = X[t, :2]
        centre = p.mean(axis=0)
        for k in range(3):
            a, b, c = t[k], t[(k + 1) % 3], t[(k + 2) % 3]
            mab, mac = (X[a, :2] + X[b, :2]) / 2, (X[a, :2] + X[c, :2]) / 2
            cells.append([X[a, :2], mab, centre, mac])
            colours.append(PALETTE[colour[node_aggregate[a]]])
            if node_aggregate[a] != node_aggregate[b]:
                borders.append([mab, centre])
    ax.add_collection(PolyCollection(cells, facecolors=colours, edgecolors=colours, linewidths=0.3))
    ax.add_collection(LineCollection(borders, colors="black", linewidths=0.9))
    nodes = np.unique(triangles)
    ax.scatter(X[nodes, 0], X[nodes, 1], s=0.6, color="0.25", linewidths=0)
    ax.set_xlim(X[:, 0].min(), X[:, 0].max())
    ax.set_ylim(X[:, 1].min(), X[:, 1].max())
    ax.set_aspect("equal")
    ax.set_xticks([])
    ax.set_yticks([])


def plot_aggregates(h, out):
    X, tets = load_mesh(h)
    pairs = node_pairs(tets)
    triangles = top_face(X, tets)
    levels = h["levels"]
    panels = []
    node_aggregate = np.arange(len(X))
    for k, aggregate in enumerate(h["aggregate"]):
        node_aggregate = np.asarray(aggregate)[node_aggregate]  # a mesh node's aggregate on level k+1
        panels.append((k, node_aggregate.copy()))
    fig, axes = plt.subplots(1, len(panels), figsize=(6.2 * len(panels), 6.6), squeeze=False)
    for ax, (k, node_aggregate) in zip(axes[0], panels):
        colour = colour_aggregates(node_aggregate, pairs)
        draw_aggregates(ax, X, triangles, node_aggregate, colour)
        count = levels[k + 1]["dofs"] // levels[k + 1]["block"]
        shown = len(np.unique(node_aggregate[np.unique(triangles)]))
        source = "mesh nodes" if k == 0 else f"level-{k} aggregates"
        ax.set_title(f"level {k} -> {k + 1}: {count} aggregates of {source}\n"
                     f"({shown} of them reach the top face)", fontsize=9)
        ax.annotate("clamped\nface", (X[:, 0].min(), X[:, 1].mean()), xytext=(-6, 0),
                    textcoords="offset points", ha="right", va="center", fontsize=8, rotation=90)
    fig.suptitle(f"Chapter 10's aggregates on {pathlib.Path(h['mesh']).name}, seen from above: each "
                 "node's cell in its aggregate's colour, borders in black", fontsize=10)
    finish(fig, out / "aggregates.png",
           "From the hierarchy chapter 10's stepper sets up (fem_figure_data hierarchy, "
           "docs/data/figures/hierarchy.json); the colours only tell neighbours apart.",
           left=0.02)


# ---- chapter 11: the matrix pattern in three orders ---------------------------------------------

def pattern_measures(rows, cols):
    """Bandwidth and envelope (ch11::order_quality's): max |i - j|, sum over rows of i - min j."""
    first = np.full(rows.max() + 1, np.iinfo(np.int64).max)
    np.minimum.at(first, rows, cols)
    return int(np.abs(rows - cols).max()), int(np.sum(np.arange(len(first)) - first))


def plot_node_orders(d, out):
    X, tets = load_mesh(d)
    rows, cols = node_pairs(tets)
    n = len(X)
    orders = [("original", "the file's order", np.arange(n), d["original"])]
    names = {"rcm": "reverse Cuthill-McKee", "morton": "Morton (Z-order curve)"}
    for key, record in d["orders"].items():
        orders.append((key, names.get(key, key), np.asarray(record["new_of_old"]), record))
    bins, window = 400, 300
    low = n // 2 - window // 2
    fig, axes = plt.subplots(2, len(orders), figsize=(5.2 * len(orders), 10.6),
                             gridspec_kw={"height_ratios": [1, 1]})
    for ax, zoom, (key, title, new_of_old, record) in zip(axes[0], axes[1], orders):
        i, j = new_of_old[rows], new_of_old[cols]
        bandwidth, profile = pattern_measures(i, j)
        if (bandwidth, profile) != (record["bandwidth"], record["profile"]):
            raise ResultsError(f"{key}: bandwidth {bandwidth} and envelope {profile} here, "
                               f"{record['bandwidth']} and {record['profile']} in the code's record")
        counts, _, _ = np.histogram2d(i, j, bins=bins, range=[[0, n], [0, n]])
        ax.imshow(np.log1p(counts), cmap="Greys", extent=(0, n, n, 0), interpolation="nearest",
                  vmin=0, vmax=np.log1p(counts.max()) * 0.6)
        ax.add_patch(Rectangle((low, low), window, window, fill=False, ec="firebrick", lw=1))
        ax.set_title(f"{title}\nbandwidth {bandwidth}, envelope {profile / n:.0f} per row",
                     fontsize=9)
        ax.set_xlabel("column (node)")
        ax.set_ylabel("row (node)")
        inside = (i >= low) & (i < low + window) & (j >= low) & (j < low + window)
        zoom.scatter(j[inside], i[inside], s=1.2, color="black", marker="s", linewidths=0)
        zoom.set_xlim(low, low + window)
        zoom.set_ylim(low + window, low)
        zoom.set_aspect("equal")
        zoom.set_title(f"rows and columns {low}-{low + window - 1}: each dot one 3x3 block "
                       f"({inside.sum()} here)", fontsize=9)
        for side in zoom.spines.values():
            side.set_color("firebrick")
    fig.suptitle(f"The system's block pattern on {pathlib.Path(d['mesh']).name} ({n} nodes, one "
                 f"3x3 block per coupled node pair). Top: each pixel {n / bins:.0f} x {n / bins:.0f} "
                 f"nodes, darker where more blocks; bottom: the {window} nodes in the red square",
                 fontsize=10)
    finish(fig, out / "node_orders.png",
           "The orders are chapter 11's node_order() (fem_figure_data node-orders, "
           "docs/data/figures/node-orders.json); bandwidth and envelope checked against its "
           "order_quality().", top=0.96)



def main(argv=None, prog=None):
    parser = command_parser(prog, __doc__)
    parser.add_argument("figure", nargs="?", choices=["hierarchy", "node-orders", "lanes"],
                        help="one family of figures (default: all)")
    parser.add_argument("--data", type=pathlib.Path, default=DATA,
                        help="the folder of hierarchy.json and node-orders.json")
    parser.add_argument("--out", type=pathlib.Path, default=ROOT / "docs" / "images")
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    try:
        if args.figure in (None, "hierarchy"):
            h = load(args.data / "hierarchy.json")
            plot_vcycle(h, args.out)
            plot_aggregates(h, args.out)
        if args.figure in (None, "node-orders"):
            plot_node_orders(load(args.data / "node-orders.json"), args.out)
        if args.figure in (None, "lanes"):
            plot_padded_lanes(args.out)
            plot_soa_batch(args.out)
    except ResultsError as e:
        die(f"fem-tools plots figures: {e}")
