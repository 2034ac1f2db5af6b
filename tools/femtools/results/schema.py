"""The results JSON's schema (README.md, "The results JSON"): the problems of a bench.json, a
scaling.json and a viewer.json; the regime sweep's is in regimes.py."""
import re

from femtools.results.common import ResultsError, load
from femtools.results.phases import all_phases


class Problems(list):
    """The problems found so far, and the typed look-up that adds one when a key is missing or of
    the wrong type."""

    def need(self, obj, key, kind, where):
        if not isinstance(obj, dict) or key not in obj:
            self.append(f"{where}: missing '{key}'")
            return None
        value = obj[key]
        if kind is float:
            ok = isinstance(value, (int, float)) and not isinstance(value, bool) and value >= 0
        else:
            ok = isinstance(value, kind) and not (kind is int and isinstance(value, bool))
        if not ok:
            self.append(f"{where}.{key}: expected {kind.__name__}"
                        f"{' >= 0' if kind is float else ''}, got {value!r}")
            return None
        return value


def validate_bench(data):
    """Returns the list of problems of a bench.json against the schema in README.md."""
    if not isinstance(data, dict):
        return ["the top level is not an object"]
    problems = Problems()
    check_header(problems, data)
    check_phases(problems, data)
    check_chapters(problems, data)
    check_solvers(problems, data)
    return list(problems)


def check_header(problems, data):
    """What the run was: mesh, scene, settings, build, machine, commit."""
    need = problems.need
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


def check_phases(problems, data):
    """The run's list of phases, where it carries one: names, the whole step last."""
    phases = data.get("phases")
    if phases is not None and not (isinstance(phases, list) and phases and phases[-1] == "step"
                                   and all(isinstance(p, str) for p in phases)):
        problems.append(f"bench.phases: expected a list of phase names ending in 'step', got {phases!r}")


def check_chapters(problems, data):
    """One row per chapter (and thread count): every phase's times, the counts, once each."""
    need = problems.need
    chapters = need(data, "chapters", list, "bench")
    if chapters is not None and not chapters:
        problems.append("bench.chapters: empty")
    phases = all_phases(data) if isinstance(data.get("phases"), list) else all_phases()
    for i, c in enumerate(chapters or []):
        where = f"chapters[{i}]"
        need(c, "chapter", str, where)
        for table in ("median_ms", "min_ms", "q1_ms", "q3_ms", "max_ms"):
            t = need(c, table, dict, where)
            for phase in phases if t is not None else []:
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


def check_solvers(problems, data):
    """The solve table, where the run has one."""
    for i, s in enumerate(data.get("solvers", [])):
        where = f"solvers[{i}]"
        problems.need(s, "name", str, where)
        for key in ("median_ms", "iterations", "allocations_per_solve"):
            problems.need(s, key, float, where)
        for key in ("setup_ms", "solve_ms"):  # absent in results written before they existed
            if isinstance(s, dict) and key in s:
                problems.need(s, key, float, where)


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
