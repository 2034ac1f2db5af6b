"""What the plotting and the docs scripts share: loading and checking the results JSON,
the phases, the poster's reported numbers, and the footer every plot and table carries."""
import json
import pathlib
import re
import sys

PHASES = ["dfdx", "compose", "constraints", "solve", "step"]
ALL_PHASES = ["forces"] + PHASES
PHASE_LABELS = {
    # common/'s element kernels in chapters 01-07; chapter 08's fused element pass, which
    # also does the work of df/dx construction and most of the composition (its dfdx is 0)
    "forces": "forces",
    "dfdx": "df/dx construction",
    "compose": "system composition",
    "constraints": "constraints",
    "solve": "solve",
    "step": "overall step",
}
# The poster's reported speedups of the optimized stepper over the naive one (per phase),
# and its solve table.
POSTER_SPEEDUPS = {"dfdx": 5.487, "compose": 21.358, "constraints": 218.79, "step": 9.849}
POSTER_SOLVE_MS = {"eigen_cg": 7.1, "eigen_cg_guess": 4.39, "pcg_ch06": 1.68}
BASELINE = "01_naive"
# The poster's numbers were measured on the cantilever on a mesh of the poster's size: they
# are drawn beside a run only when the run is that one (any other mesh or scene would compare
# unlike with unlike).
POSTER_MESH, POSTER_SCENE = "plate_poster.msh", "cantilever"


def comparable_to_poster(data):
    return data.get("mesh", {}).get("file") == POSTER_MESH and data.get("scene") == POSTER_SCENE


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


def validate_bench(data):
    """Returns the list of problems of a bench.json against the schema in README.md."""
    problems = []

    def need(obj, key, kind, where):
        if not isinstance(obj, dict) or key not in obj:
            problems.append(f"{where}: missing '{key}'")
            return None
        value = obj[key]
        if kind is float:
            ok = isinstance(value, (int, float)) and not isinstance(value, bool) and value >= 0
        else:
            ok = isinstance(value, kind) and not (kind is int and isinstance(value, bool))
        if not ok:
            problems.append(f"{where}.{key}: expected {kind.__name__}"
                            f"{' >= 0' if kind is float else ''}, got {value!r}")
            return None
        return value

    if not isinstance(data, dict):
        return ["the top level is not an object"]
    need(data, "schema_version", int, "bench")
    mesh = need(data, "mesh", dict, "bench")
    if mesh is not None:
        need(mesh, "file", str, "mesh")
        need(mesh, "nodes", int, "mesh")
        need(mesh, "tets", int, "mesh")
    need(data, "scene", str, "bench")
    for key in ("steps", "warmup_steps", "cg_max_iterations"):
        need(data, key, int, "bench")
    for key in ("dt", "cg_tolerance"):
        need(data, key, float, "bench")
    build = need(data, "build", dict, "bench")
    if build is not None:
        for key in ("compiler", "flags", "build_type", "eigen"):
            need(build, key, str, "build")
    machine = need(data, "machine", dict, "bench")
    if machine is not None:
        need(machine, "cpu", str, "machine")
        if "busy" in machine and not isinstance(machine["busy"], bool):
            problems.append(f"machine.busy: expected a bool, got {machine['busy']!r}")
        if machine.get("other_cpus") is not None:
            need(machine, "other_cpus", float, "machine")
        problems += validate_machine_record(machine)
    uncommitted = data.get("uncommitted")
    if uncommitted is not None and not (isinstance(uncommitted, list) and
                                        all(isinstance(f, str) for f in uncommitted)):
        problems.append(f"bench.uncommitted: expected a list of paths or null, got {uncommitted!r}")
    need(data, "commit", str, "bench")
    chapters = need(data, "chapters", list, "bench")
    if chapters is not None and not chapters:
        problems.append("bench.chapters: empty")
    for i, c in enumerate(chapters or []):
        where = f"chapters[{i}]"
        need(c, "chapter", str, where)
        for table in ("median_ms", "min_ms", "q1_ms", "q3_ms", "max_ms"):
            t = need(c, table, dict, where)
            for phase in ALL_PHASES if t is not None else []:
                need(t, phase, float, f"{where}.{table}")
        for key in ("allocations_per_step", "cg_iterations", "relative_residual"):
            need(c, key, float, where)
        if isinstance(c, dict) and "threads" in c and need(c, "threads", int, where) is not None \
                and c["threads"] < 1:
            problems.append(f"{where}.threads: expected >= 1, got {c['threads']}")
        if isinstance(c, dict) and "source_hash" in c and not (
                isinstance(c["source_hash"], str) and re.fullmatch(r"[0-9a-f]{64}", c["source_hash"])):
            problems.append(f"{where}.source_hash: expected a SHA-256 in hex, got {c['source_hash']!r}")
    rows = [c.get("chapter") for c in chapters or [] if isinstance(c, dict)]
    for row in sorted({r for r in rows if rows.count(r) > 1}):
        problems.append(f"bench.chapters: the row {row} stands {rows.count(row)} times (a chapter "
                        "measured twice in one run)")
    for i, s in enumerate(data.get("solvers", [])):
        where = f"solvers[{i}]"
        need(s, "name", str, where)
        for key in ("median_ms", "iterations", "allocations_per_solve"):
            need(s, key, float, where)
        for key in ("setup_ms", "solve_ms"):  # absent in results written before they existed
            if isinstance(s, dict) and key in s:
                need(s, key, float, where)
    return problems


# The machine record (common/machine_record.hpp): absent in runs recorded before it existed,
# whole and typed when there.
MACHINE_RECORD = {"vendor": str, "family": int, "model": int, "model_name": str, "isa_build": str,
                  "isa_cpu": str, "features_build": list, "features_cpu": list, "cores": int,
                  "hardware_threads": int, "caches": list, "memory_bytes": int}
ISA_NAMES = ("SSE2", "SSE4.2", "AVX", "AVX2", "AVX-512")


def validate_machine_record(machine):
    if not any(key in machine for key in MACHINE_RECORD):
        return []
    problems = []
    for key, kind in MACHINE_RECORD.items():
        value = machine.get(key)
        if not isinstance(value, kind) or isinstance(value, bool):
            problems.append(f"machine.{key}: expected {kind.__name__}, got {value!r}")
    for key in ("isa_build", "isa_cpu"):
        if isinstance(machine.get(key), str) and machine[key] not in ISA_NAMES + ("unknown",):
            problems.append(f"machine.{key}: expected one of {', '.join(ISA_NAMES)}, got {machine[key]!r}")
    for i, c in enumerate(machine.get("caches") or []):
        if not isinstance(c, dict) or not all(isinstance(c.get(k), t) for k, t in
                                              (("level", int), ("type", str), ("bytes", int), ("shared_by", int))):
            problems.append(f"machine.caches[{i}]: expected level, type, bytes, shared_by, got {c!r}")
    return problems


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


def validate_scaling(data):
    problems = []
    if not isinstance(data, dict):
        return ["the top level is not an object"]
    for key in ("scene", "runs", "build", "machine"):
        if key not in data:
            problems.append(f"scaling: missing '{key}'")
    for i, run in enumerate(data.get("runs", [])):
        for key in ("chapter", "nodes", "step_ms", "solve_ms"):
            if key not in run:
                problems.append(f"runs[{i}]: missing '{key}'")
    return problems


def validate_viewer(data):
    """Problems of a results/viewer.json (fem-tools runs viewer-fps): one fem_viewer report per run."""
    if not isinstance(data, dict) or not isinstance(data.get("runs"), list) or not data["runs"]:
        return ["viewer: expected an object with a non-empty 'runs' list"]
    problems = []
    for i, run in enumerate(data["runs"]):
        for key in ("run", "chapter", "nodes", "frames", "frames_per_second", "mean_step_ms",
                    "width", "height", "renderer", "cpu", "compiler", "flags"):
            if not isinstance(run, dict) or key not in run:
                problems.append(f"runs[{i}]: missing '{key}'")
    return problems


def load_checked(path, scaling=False, viewer=False):
    data = load(path)
    problems = (validate_scaling(data) if scaling else validate_viewer(data) if viewer
                else validate_bench(data))
    if problems:
        raise ResultsError(f"{path}: does not match the schema:\n  " + "\n  ".join(problems))
    return data


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
