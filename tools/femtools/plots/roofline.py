"""The roofline plot of `fem_lessons roofline --json FILE` (its "data"): the machine's roofs
(read bandwidth of each level of the memory hierarchy and the peak multiply-add rate, as
measured) and one point per chapter and phase, at the phase's arithmetic intensity (flops per
byte of traffic counted from the chapter's data: reads, writes and the line reads of
allocating writes) and the rate it achieved (those flops over its measured median time). A
panel per thread count: the cache-aware roofline (Ilic, Pratas & Sousa, IEEE CAL 2014), one
roof per level, after the DRAM roofline of Williams, Waterman & Patterson (CACM 52(4), 2009).

    fem-tools plots roofline results/roofline.json --out results/roofline.png
    fem-tools plots roofline docs/data/lessons/roofline.json --check

A phase's bound is max(bytes' time, flops' time) + its waiting (its parallel regions and
barriers, counted per phase, at their measured costs), as the data's "bound" says; the plot rings
the phases that waiting holds (the largest of the three). Data recorded before the phases counted
their waiting have no "bound": read with no waiting, and --check says to re-record them.

--check draws nothing: it exits 1 if a phase ran faster than its bound allows (measured time
below the bound: the model is broken there, and committed data must not hold one), if the data
lack a field the plot and the page read, or if a phase's bound or "held by" is not the one its
terms give; data recorded with `fem_lessons roofline --provisional REASON` (a placeholder, the
page says so in bold) get warnings instead.
"""
import json
import pathlib
import sys

import matplotlib
import matplotlib.pyplot as plt
import numpy as np

from femtools.args import command_parser
from femtools.files import replacing
from femtools.results.phases import marker, parts

PHASE_FIELDS = ("phase", "bytes_read", "bytes_written", "bytes_allocated", "bytes_zeroed", "flops_double",
                "flops_float", "working_set", "level", "bound_s", "memory_s", "arithmetic_s", "measured_s")
# The roofs each level must have: a phase's written bytes are priced at the write roof (allocating
# stores), the update roof (stores to lines the pass read first) or the zeroing roof (A's blocks zeroed).
LEVEL_ROOFS = ("read", "write", "update", "zero")
# Each phase's own synchronizations, their waiting and which of the three holds it: in data that
# say how the bound combines them (data["bound"]).
WAITING_FIELDS = ("regions", "barriers", "waiting_s", "held_by")
BOUND = "max(memory_s, arithmetic_s) + waiting_s"


def held_by(p):
    """Which of a phase's three least times holds it (apps/roofline/roofs.cpp's held_by)."""
    bytes_s, flops_s, waiting_s = p["memory_s"], p["arithmetic_s"], p.get("waiting_s", 0.0)
    if waiting_s > max(bytes_s, flops_s):
        return "waiting"
    return "bytes" if bytes_s >= flops_s else "flops"


def bound_problem(p):
    """Why a phase's bound and "held by" are not the ones its terms give, or None."""
    expected = max(p["memory_s"], p["arithmetic_s"]) + p["waiting_s"]
    if abs(p["bound_s"] - expected) > 1e-9 * max(expected, 1e-12):
        return f"bound {p['bound_s']:.6g} s is not {BOUND} = {expected:.6g} s"
    if p["held_by"] != held_by(p):
        return f"held by {p['held_by']}, but its largest term is {held_by(p)}"
    return None


def traffic(p):
    """A phase's bytes: reads, writes and the line reads its allocating writes cost."""
    return p["bytes_read"] + p["bytes_written"] + p["bytes_allocated"]


def phase_problem(p, with_waiting):
    """Why --check refuses one phase, or None."""
    missing = [f for f in PHASE_FIELDS + (WAITING_FIELDS if with_waiting else ()) if f not in p]
    if missing:
        return f"no {', '.join(missing)}"
    return bound_problem(p) if with_waiting else None


def problems(data):
    """What --check refuses: missing fields, bounds not made of their terms, and phases measured
    faster than their bound."""
    found = []
    for roof in data.get("roofs", []):
        for level in roof["levels"]:
            for kind in LEVEL_ROOFS:
                if kind not in level:
                    found.append(f"roofs at {roof['threads']} thread(s): level {level['name']} has no {kind} roof")
    if "bound" in data and data["bound"] != BOUND:
        found.append(f"the bound is {data['bound']!r}; this check knows {BOUND!r}")
    for r in data.get("runs", []):
        name = f"{r['chapter']}@{r['threads']} on {r['mesh']}"
        for p in r["phases"]:
            problem = phase_problem(p, "bound" in data)
            if problem:
                found.append(f"{name} {p.get('phase', '?')}: {problem}")
            elif p["measured_s"] < p["bound_s"]:
                found.append(f"{name} {p['phase']}: measured {p['measured_s'] * 1e3:.3g} ms, below its bound "
                             f"{p['bound_s'] * 1e3:.3g} ms ({100 * p['bound_s'] / p['measured_s']:.0f}% of the "
                             "bound): a broken model")
    return found


# One marker per phase of the step (results/phases.py).
MARKERS = {p: marker(p) for p in parts()}


def roofs(ax, roof, x):
    peak = roof["peak_double"] / 1e9
    for level in roof["levels"]:
        bw = level["read"] / 1e9
        ax.plot(x, np.minimum(peak, x * bw), lw=1, color="0.35")
        ax.text(x[0] * 1.3, x[0] * 1.3 * bw * 1.15, f"{level['name']} {bw:.0f} GB/s", fontsize=7,
                color="0.25")
        # The write roof of the level, dotted: a phase that mostly writes sits under it.
        ax.plot(x, np.minimum(peak, x * level["write"] / 1e9), lw=0.8, color="0.55", ls=":")
    ax.axhline(peak, lw=1, color="0.35", ls="-")
    ax.axhline(roof["peak_float"] / 1e9, lw=1, color="0.6", ls="--")
    ax.text(x[-1], peak * 1.08, f"double peak {peak:.0f} Gflop/s", fontsize=7, ha="right")
    ax.text(x[-1], roof["peak_float"] / 1e9 * 1.08, "float peak", fontsize=7, ha="right", color="0.4")


def points(ax, runs, threads):
    chapters = sorted({r["chapter"] for r in runs})
    colours = {c: matplotlib.colormaps["tab20"](i % 20) for i, c in enumerate(chapters)}
    meshes = list(dict.fromkeys(r["mesh"] for r in runs))  # the run's mesh first, then the further ones
    for r in runs:
        if r["threads"] != threads:
            continue
        for p in r["phases"]:
            flops = p["flops_double"] + p["flops_float"]
            if flops <= 0 or p["measured_s"] <= 0:
                continue
            hollow = meshes.index(r["mesh"]) > 0  # a further mesh: hollow markers
            c = colours[r["chapter"]]
            x, y = flops / traffic(p), flops / p["measured_s"] / 1e9
            ax.scatter(x, y, marker=MARKERS.get(p["phase"], "x"), s=28, facecolors="none" if hollow else c,
                       edgecolors=c, linewidths=1)
            if held_by(p) == "waiting":
                ax.scatter(x, y, marker="o", s=110, facecolors="none", edgecolors="C3", linewidths=0.8)
    return chapters, colours, meshes


def legend(fig, chapters, colours, meshes):
    handles = [plt.Line2D([], [], ls="", marker="o", color=colours[c], label=c) for c in chapters]
    handles += [plt.Line2D([], [], ls="", marker=m, color="0.3", label=p) for p, m in MARKERS.items()]
    handles += [plt.Line2D([], [], ls="", marker="o", color="0.3", label=meshes[0])]
    handles += [plt.Line2D([], [], ls="", marker="o", mfc="none", color="0.3", label=m) for m in meshes[1:]]
    handles += [plt.Line2D([], [], ls="", marker="o", ms=9, mfc="none", color="C3", label="held by waiting")]
    fig.legend(handles=handles, loc="center right", fontsize=7, frameon=False)


def check(path, data):
    """--check: the data's problems on stderr; exit status 1 if any (warnings only for data
    recorded as provisional)."""
    found = problems(data)
    provisional = data.get("provisional")
    for line in found:
        print(f"fem-tools plots roofline: {path}: {'warning: ' if provisional else ''}{line}", file=sys.stderr)
    if provisional:
        print(f"{path}: provisional data ({provisional}): re-record it before it is read")
        return 0
    if "bound" not in data:
        print(f"{path}: recorded before each phase counted its waiting (no \"bound\"): read with no "
              "waiting; re-record it (fem_lessons roofline)")
    if not found:
        print(f"{path}: every phase at or under its bound")
    return 1 if found else 0


def draw(data, out):
    panels = data["roofs"]
    fig, axes = plt.subplots(1, len(panels), figsize=(5.2 * len(panels) + 2.2, 4.6), squeeze=False)
    x = np.logspace(-3, 2, 200)
    for ax, roof in zip(axes[0], panels):
        roofs(ax, roof, x)
        chapters, colours, meshes = points(ax, data["runs"], roof["threads"])
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("arithmetic intensity (flop / byte, counted)")
        ax.set_ylabel("Gflop/s achieved")
        ax.set_title(f"{roof['threads']} thread(s)", fontsize=10)
        ax.set_ylim(1e-3, roof["peak_float"] / 1e9 * 3)
    legend(fig, chapters, colours, meshes)
    if data.get("provisional"):
        fig.suptitle(f"PROVISIONAL, not to be read: {data['provisional']}", fontsize=9, color="C3")
    fig.tight_layout(rect=(0, 0, 1 - 2.0 / fig.get_figwidth(), 1))
    out.parent.mkdir(parents=True, exist_ok=True)
    with replacing(out) as tmp:
        fig.savefig(tmp, dpi=130)
    print(f"wrote {out}")


def main(argv=None, prog=None):
    parser = command_parser(prog, __doc__)
    parser.add_argument("json", type=pathlib.Path)
    parser.add_argument("--out", type=pathlib.Path, help="the PNG to write")
    parser.add_argument("--check", action="store_true", help="check the data, draw nothing")
    args = parser.parse_args(argv)
    if not args.check and args.out is None:
        parser.error("give --out PNG, or --check")
    record = json.loads(args.json.read_text())
    data = record.get("data")
    if not data or not data.get("roofs"):
        print(f"fem-tools plots roofline: {args.json} has no roofline data (fem_lessons roofline --json)",
              file=sys.stderr)
        return 1
    if args.check:
        return check(args.json, data)
    draw(data, args.out)
    return 0
