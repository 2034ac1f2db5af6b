"""What the plotting and the docs tools share: loading the results JSON, the chapters' names and
colours, and the footer every plot and table carries."""
import json
import pathlib
import sys

BASELINE = "01_naive"


def run_label(data):
    """What a plot's title says about the run: the scene and the mesh."""
    mesh = data.get("mesh")
    where = f"{mesh['file']}, {mesh['nodes']} nodes" if mesh else "the beam series"
    return f"{data['scene']} scene, {where}"


def chapter_color(chapter, variant_of=""):
    """One colour per chapter in every plot: matplotlib's tab20 pairs, the dark one for the
    chapter NN of the course, the light one of the same hue for a student's variant of it;
    from chapter 11 on (tab20 has ten hues) tab20b's groups of four shades, the darkest for the
    chapter and the third for its variants."""
    import matplotlib
    try:
        number = int(chapter[:2])
    except ValueError:
        return "0.4"
    if number > 10:
        return matplotlib.colormaps["tab20b"].colors[(4 * (number - 11)) % 20 + (2 if variant_of else 0)]
    return matplotlib.colormaps["tab20"].colors[(2 * (number - 1)) % 20 + (1 if variant_of else 0)]


class ResultsError(Exception):
    pass


def chapter_dir(name):
    """The chapter directory of a result row: '09_threads@2' (chapter 09 on 2 threads) -> '09_threads'."""
    return name.split("@")[0]


def load(path):
    path = pathlib.Path(path)
    if not path.exists():
        raise ResultsError(f"{path}: no such file (run ./tutorial.sh bench first)")
    try:
        return json.loads(path.read_text())
    except json.JSONDecodeError as e:
        raise ResultsError(f"{path}: not valid JSON ({e})") from e


def machine_summary(machine):
    """The instruction set and the cores of a run, for a caption or a footnote: "AVX2 build on
    an AVX-512 CPU, 2 cores / 2 threads"; what older runs recorded otherwise."""
    m = machine
    if "isa_build" not in m:
        return f"{m.get('threads', '?')} threads, instruction set not recorded"
    cores = m["cores"] if m["cores"] >= 0 else "?"
    return f"{m['isa_build']} build on an {m['isa_cpu']} CPU, {cores} cores / {m['hardware_threads']} threads"


def cache_summary(machine):
    """"L1d 48 KiB, L2 1 MiB, L3 32 MiB" from a machine record ("" when not recorded)."""
    parts = []
    for c in machine.get("caches", []):
        if c["type"] == "Instruction":
            continue
        size = c["bytes"] >> 10
        text = f"{size >> 10} MiB" if size >= 1024 and size % 1024 == 0 else f"{size} KiB"
        parts.append(f"L{c['level']}{'d' if c['type'] == 'Data' else ''} {text}")
    return ", ".join(parts)


def uncommitted_summary(data):
    """What a run measured beyond its commit (fem_bench's "uncommitted"): the chapter folders
    and other files, e.g. 'chapters/10_mine/, common/stepper.cpp'; "" when nothing."""
    files = data.get("uncommitted") or []
    parts = []
    for f in files:
        p = pathlib.PurePosixPath(f)
        part = f"chapters/{p.parts[1]}/" if len(p.parts) > 2 and p.parts[0] == "chapters" else f
        if part not in parts:
            parts.append(part)
    return ", ".join(parts)


def busy_note(data):
    """The warning a run on a busy machine carries: other processes' CPU use during the run
    (fem_bench's machine.busy and machine.other_cpus, common/machine_load.hpp); "" otherwise."""
    m = data.get("machine", {})
    if not m.get("busy"):
        return ""
    return (f"BUSY MACHINE: other processes used {m.get('other_cpus', '?'):.2g} of its "
            f"{m.get('threads', '?')} cores during the run; the times are not the code's alone")


def footer(data):
    b, m = data["build"], data["machine"]
    mesh = data.get("mesh")
    where = (f"{mesh['file']} ({mesh['nodes']} nodes, {mesh['tets']} tets), "
             f"{data['scene']}, {data.get('steps', '?')} steps, " if mesh else f"{data['scene']}, ")
    changed = uncommitted_summary(data)
    busy = busy_note(data)
    return (f"{where}CG tol {data['cg_tolerance']:g} | {m['cpu']}, {machine_summary(m)} | "
            f"{b['compiler']} {b['flags']} | Eigen {b['eigen']} | commit {data.get('commit', '?')}"
            + (f" + uncommitted {changed}" if changed else "") + (f"\n{busy}" if busy else ""))


def die(message):
    print(message, file=sys.stderr)
    sys.exit(2)
