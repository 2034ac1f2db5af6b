"""Renders a VTK series written by fem_sim (out/sim/NAME.pvd) to an animated GIF with
matplotlib: the boundary triangles of the tetrahedra, shaded by displacement.

    fem-tools plots gif out/sim/cantilever.pvd --out docs/images/cantilever.gif
"""
import pathlib
import re
import sys
from collections import Counter

import matplotlib.pyplot as plt
import numpy as np
from matplotlib import animation
from mpl_toolkits.mplot3d.art3d import Poly3DCollection

from femtools.args import command_parser

from femtools.files import replacing


def data_array(text, name):
    match = re.search(rf'<DataArray[^>]*Name="{name}"[^>]*>(.*?)</DataArray>', text, re.S)
    if match is None:
        raise ValueError(f"no DataArray {name}")
    return np.array(match.group(1).split(), dtype=float)


def read_frame(path):
    text = path.read_text()
    points = np.array(re.search(r"<Points>\s*<DataArray[^>]*>(.*?)</DataArray>", text, re.S)
                      .group(1).split(), dtype=float).reshape(-1, 3)
    tets = data_array(text, "connectivity").astype(int).reshape(-1, 4)
    displacement = data_array(text, "displacement").reshape(-1, 3)
    return points, tets, np.linalg.norm(displacement, axis=1)


def boundary(tets):
    faces = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]
    all_faces = [tuple(t[list(f)]) for t in tets for f in faces]
    count = Counter(tuple(sorted(f)) for f in all_faces)
    return np.array([f for f in all_faces if count[tuple(sorted(f))] == 1])


def main(argv=None, prog=None):
    parser = command_parser(prog, __doc__)
    parser.add_argument("pvd", type=pathlib.Path)
    parser.add_argument("--out", type=pathlib.Path, default=pathlib.Path("docs/images/cantilever.gif"))
    parser.add_argument("--fps", type=int, default=15)
    parser.add_argument("--max-frames", type=int, default=60)
    args = parser.parse_args(argv)
    if not args.pvd.exists():
        sys.exit(f"fem-tools plots gif: {args.pvd} does not exist (run ./tutorial.sh sim first)")
    files = re.findall(r'file="([^"]+)"', args.pvd.read_text())
    times = [float(t) for t in re.findall(r'timestep="([^"]+)"', args.pvd.read_text())]
    if not files:
        sys.exit(f"fem-tools plots gif: {args.pvd} lists no frames")
    stride = max(1, len(files) // args.max_frames)
    files, times = files[::stride], times[::stride]
    frames = [read_frame(args.pvd.parent / f) for f in files]
    triangles = boundary(frames[0][1])
    everything = np.vstack([p for p, _, _ in frames])
    lo, hi = everything.min(axis=0), everything.max(axis=0)
    vmax = max(d.max() for _, _, d in frames) or 1.0

    fig = plt.figure(figsize=(6.4, 4.8))
    ax = fig.add_subplot(projection="3d")

    def draw(k):
        ax.clear()
        points, _, disp = frames[k]
        colors = plt.cm.viridis(disp[triangles].mean(axis=1) / vmax)
        ax.add_collection3d(Poly3DCollection(points[triangles], facecolors=colors, edgecolor="none"))
        ax.set_xlim(lo[0], hi[0])
        ax.set_ylim(lo[1], hi[1])
        ax.set_zlim(lo[2], hi[2])
        ax.set_box_aspect(hi - lo + 1e-9)
        ax.view_init(elev=20, azim=-60)
        ax.set_axis_off()
        ax.set_title(f"{args.pvd.stem}, t = {times[k]:.2f} s (colour: displacement)", fontsize=9)

    anim = animation.FuncAnimation(fig, draw, frames=len(frames))
    args.out.parent.mkdir(parents=True, exist_ok=True)
    with replacing(args.out) as tmp:
        anim.save(tmp, writer=animation.PillowWriter(fps=args.fps))
    print(f"wrote {args.out} ({len(frames)} frames)")
