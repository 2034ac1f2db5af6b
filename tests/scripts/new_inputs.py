#!/usr/bin/env python3
"""Inputs that no review had tried (issue 65): odd option values, odd mesh files, odd
environments, each run through the programs with what a user expects of it asserted.

usage: new_inputs.py BUILD_DIR

Each case is a command and an expectation: "ok" (exit 0, no NaN printed) or a refusal (exit 1
or 2 with a message matching a pattern, naming the cause). Never a signal, a hang (each run
has a timeout), a Python traceback or an uncaught C++ exception. The runs are short (1-2 steps
of beam_500 or an 8-node cube, --every 0): nothing is timed.
"""
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
BEAM = ROOT / "meshes" / "beam_500.msh"

# The unit cube in six tetrahedra around the diagonal 0-7 (corner i at the bits of i).
CORNERS = [(i & 1, (i >> 1) & 1, (i >> 2) & 1) for i in range(8)]
CUBE_TETS = [(0, 1, 3, 7), (0, 3, 2, 7), (0, 2, 6, 7), (0, 6, 4, 7), (0, 4, 5, 7), (0, 5, 1, 7)]


def oriented(tet, points):
    a, b, c, d = (points[i] for i in tet)
    u, v, w = ([q[k] - a[k] for k in range(3)] for q in (b, c, d))
    det = (u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0])
           + u[2] * (v[0] * w[1] - v[1] * w[0]))
    return tet if det > 0 else (tet[0], tet[2], tet[1], tet[3])


TETS = [oriented(t, CORNERS) for t in CUBE_TETS]


def msh22(points=CORNERS, tets=TETS, first_tag=1, sep=" ", header="2.2 0 8", extra_before="",
          extra_after="", node_lines=None, element_lines=None, elem_tags="2 1 1"):
    nodes = node_lines if node_lines is not None else [
        sep.join([str(first_tag + i)] + [repr(float(c)) for c in p]) for i, p in enumerate(points)]
    elems = element_lines if element_lines is not None else [
        sep.join([str(e + 1), "4", elem_tags] + [str(first_tag + n) for n in t])
        for e, t in enumerate(tets)]
    return (f"$MeshFormat\n{header}\n$EndMeshFormat\n{extra_before}"
            f"$Nodes\n{len(nodes)}\n" + "\n".join(nodes) + "\n$EndNodes\n"
            f"$Elements\n{len(elems)}\n" + "".join(e + "\n" for e in elems) + "$EndElements\n"
            + extra_after)


def msh41(points=CORNERS, tets=TETS, node_block_count=None, elem_block_count=None,
          parametric=0, first_tag=1):
    n, m = len(points), len(tets)
    nb = n if node_block_count is None else node_block_count
    eb = m if elem_block_count is None else elem_block_count
    last = first_tag + n - 1
    out = ["$MeshFormat", "4.1 0 8", "$EndMeshFormat", "$Nodes",
           f"1 {n} {first_tag} {last}", f"3 1 {parametric} {nb}"]
    out += [str(first_tag + i) for i in range(n)]
    uvw = " 0.5 0.5 0.5" if parametric else ""
    out += [" ".join(repr(float(c)) for c in p) + uvw for p in points]
    out += ["$EndNodes", "$Elements", f"1 {m} 1 {m}", f"3 1 4 {eb}"]
    out += [" ".join([str(e + 1)] + [str(first_tag + k) for k in t]) for e, t in enumerate(tets)]
    out += ["$EndElements"]
    return "\n".join(out) + "\n"


class Runner:
    def __init__(self, build):
        self.build = Path(build).resolve()
        self.work = Path(tempfile.mkdtemp(prefix="fem_new_inputs_"))
        self.results = []  # (name, passed, detail)
        self.known = []  # (name, why): wrong, not yet fixed, said at the end, not counted right

    def run(self, name, argv, expect, pattern="", env=None, timeout=120, stdout=None):
        """stdout: a file to write the standard output to ("/dev/full"), or "closed"."""
        full_env = dict(os.environ)
        full_env.pop("OMP_NUM_THREADS", None)
        full_env.update(env or {})
        out_file = None if stdout in (None, "closed") else open(stdout, "w")
        closing = (lambda: os.close(1)) if stdout == "closed" else None
        try:
            p = subprocess.run(argv, cwd=self.work, env=full_env, timeout=timeout,
                               stdout=out_file or subprocess.PIPE, stderr=subprocess.PIPE,
                               preexec_fn=closing)
            p.stdout = p.stdout or b""
        except subprocess.TimeoutExpired:
            self.results.append((name, False, f"hung (no end within {timeout} s)"))
            return
        out = p.stdout.decode("utf-8", "replace") + p.stderr.decode("utf-8", "replace")
        problems = []
        if p.returncode < 0:
            problems.append(f"killed by signal {-p.returncode}")
        if "Traceback" in out or "terminate called" in out:
            problems.append("a traceback or an uncaught exception")
        if expect == "ok":
            if p.returncode != 0:
                problems.append(f"rc {p.returncode}, expected 0")
            if re.search(r"\bnan\b", out, re.IGNORECASE):
                problems.append("NaN printed")
        else:
            if p.returncode not in (1, 2):
                problems.append(f"rc {p.returncode}, expected a refusal (1 or 2)")
        if pattern and not re.search(pattern, out):
            problems.append(f"the output does not match /{pattern}/")
        detail = "; ".join(problems)
        if problems:
            detail += " -- " + " ".join(map(str, argv[1:]))[:200] + "\n    " + out.strip()[-400:]
        self.results.append((name, not problems, detail))

    def mesh(self, name, text):
        path = self.work / name
        (path.write_bytes if isinstance(text, bytes) else path.write_text)(text)
        return str(path)

    def sim(self, *args):
        return [str(self.build / "fem_sim"), "--every", "0", "--steps", "2", *args]


def sim_options(r):
    beam = str(BEAM)
    sim = lambda *a: r.sim("--mesh", beam, *a)  # noqa: E731
    r.run("sim: '--' then an option", sim("--", "--E", "1e5"), "refuse", r"'--'")
    r.run("sim: a positional argument after the options", sim("extra"), "refuse",
          r"unexpected argument 'extra'")
    r.run("sim: a positional argument between options", r.sim("x", "--mesh", beam), "refuse",
          r"unexpected argument 'x'")
    r.run("sim: an option with no value at the end", sim("--steps"), "refuse", r"needs a value")
    r.run("sim: Arabic-Indic digits for --E", sim("--E", "١٠٠٠٠٠"), "refuse",
          r"--E expects a finite number")
    r.run("sim: full-width digits for --steps", sim("--steps", "２"), "refuse", r"--steps")
    r.run("sim: --help after a bad value", sim("--E", "0", "--help"), "ok", r"usage: fem_sim")
    r.run("sim: --help before a bad value", sim("--help", "--E", "0"), "ok", r"usage: fem_sim")
    r.run("sim: --threads 1e20 digits", sim("--threads", "9" * 20), "refuse", r"out of range")
    r.run("sim: --steps 1e20 digits", sim("--steps", "9" * 20), "refuse", r"out of range")
    r.run("sim: --watch the last node", sim("--watch", "514"), "ok", r"node 514 at")
    r.run("sim: --watch one past the last node", sim("--watch", "515"), "refuse",
          r"515 nodes")
    r.run("sim: --watch -2", sim("--watch", "-2"), "refuse", r"-1 for none")
    r.run("sim: --nu next to 0.5 (diverges, said)", sim("--nu", "0.4999999999"), "refuse",
          r"diverged")
    r.run("sim: --verbose twice", sim("--verbose", "--verbose"), "ok")
    r.run("sim: --every larger than --steps", sim("--every", "99999999", "--out", "e"), "ok",
          r"1 frames")
    r.run("sim: --scene ''", sim("--scene", ""), "refuse", r"unknown scene ''")
    r.run("sim: --chapter given twice, the last empty", sim("--chapter", "14", "--chapter", ""),
          "refuse", r"unknown chapter ''")
    r.run("sim: --chapter with a leading space", sim("--chapter", " 14"), "refuse",
          r"unknown chapter")
    r.run("sim: --E= (empty after =)", sim("--E="), "refuse", r"expects a finite number")
    r.run("sim: --=1", sim("--=1"), "refuse", r"unknown option")
    r.run("sim: a lone -", sim("-"), "refuse", r"unexpected argument '-'")
    r.run("sim: --mesh= (empty)", r.sim("--mesh="), "refuse", r"empty path")
    r.run("sim: --out '' with frames", sim("--every", "1", "--out", ""), "refuse",
          r"--out")
    r.run("sim: --scene sliding then cantilever (last wins)",
          sim("--scene", "sliding", "--scene", "cantilever"), "ok", r"cantilever on")
    r.run("sim: --watch ''", sim("--watch", ""), "refuse", r"--watch expects an integer")
    r.run("sim: --steps with a trailing unit", sim("--steps", "2s"), "refuse",
          r"expects an integer")
    r.run("sim: --dt with a comma decimal", sim("--dt", "0,01"), "refuse", r"--dt")
    r.run("sim: --E with thousands separators", sim("--E", "100,000"), "refuse", r"--E")
    r.run("sim: --E with a NUL-free control char", sim("--E", "1e5\t"), "refuse", r"--E")
    r.run("sim: --mesh a unicode name that does not exist", r.sim("--mesh", "ünï©ødé.msh"),
          "refuse", r"cannot open")
    r.run("sim: an option spelled with one dash and =", sim("-E=1"), "refuse",
          r"unexpected argument")
    r.run("sim: --HELP (case)", sim("--HELP"), "refuse", r"unknown option")


def viewer_options(r):
    if not (r.build / "fem_viewer").exists():  # built only where its libraries are
        return
    v = lambda *a: [str(r.build / "fem_viewer"), "--mesh", str(BEAM), *a]  # noqa: E731
    env = {"DISPLAY": "", "WAYLAND_DISPLAY": ""}
    r.run("viewer: --help", [str(r.build / "fem_viewer"), "--help"], "ok", r"usage")
    r.run("viewer: --width 0", v("--width", "0"), "refuse", r"\[64, 8192\]", env)
    r.run("viewer: --height 1e11 digits", v("--height", "99999999999"), "refuse",
          r"out of range", env)
    r.run("viewer: --width 1e3", v("--width", "1e3"), "refuse", r"expects an integer", env)
    r.run("viewer: --replay-drag of three numbers", v("--frames", "1", "--replay-drag",
                                                      "0.1,0.1,0.2"), "refuse", r"x0,y0,x1,y1",
          env)
    # An empty file name or drag is a mistake ("--report $OUT" with OUT unset): refused before
    # the window opens, as --mesh '' is, not taken for "no report".
    r.run("viewer: --report ''", v("--frames", "1", "--report", ""), "refuse",
          r"--report: an empty", env)
    r.run("viewer: --screenshot ''", v("--frames", "1", "--screenshot", ""), "refuse",
          r"--screenshot: an empty", env)
    r.run("viewer: --replay-drag ''", v("--frames", "1", "--replay-drag", ""), "refuse",
          r"--replay-drag: an empty", env)
    r.run("viewer: a positional argument", v("x"), "refuse", r"unexpected argument", env)


def bench_options(r):
    b = lambda *a: [str(r.build / "fem_bench"), "--mesh", str(BEAM), *a]  # noqa: E731
    r.run("bench: --threads ' '", b("--threads", " "), "refuse", r"--threads expects integers")
    r.run("bench: --no-json and --json", b("--no-json", "--json", "x.json"), "refuse",
          r"contradict")
    r.run("bench: --warmup 1e11 digits", b("--warmup", "99999999999"), "refuse", r"out of range")
    r.run("bench: --threads 1,-1", b("--threads", "1,-1"), "refuse", r">= 1")
    r.run("bench: --chapters 14,99", b("--chapters", "14,99"), "refuse", r"unknown chapter '99'")
    r.run("bench: a positional argument after options", b("--chapters", "14", "x"), "refuse",
          r"unexpected argument")
    r.run("bench: --json ''", b("--json", ""), "refuse", r"--json: an empty value")
    r.run("bench: --out ''", b("--out", ""), "refuse", r"--out: an empty value")
    r.run("bench: --help", [str(r.build / "fem_bench"), "--help"], "ok", r"usage: fem_bench")
    r.run("lessons: --help", [str(r.build / "fem_lessons"), "--help"], "ok", r"usage")
    r.run("lessons: an empty lesson name", [str(r.build / "fem_lessons"), ""], "refuse", r".")
    r.run("lessons: a unicode lesson name", [str(r.build / "fem_lessons"), "spmv✓"], "refuse",
          r"spmv✓")
    r.run("lessons: spmv --steps ''", [str(r.build / "fem_lessons"), "spmv", "--steps", ""],
          "refuse", r"--steps")
    r.run("lessons: phase-owners --check ''",
          [str(r.build / "fem_lessons"), "phase-owners", "--check", ""], "refuse", r"--check: an empty value")
    # Each refused before any measurement: a lesson run for nothing, or every lesson recorded
    # into a folder that could not be made, is what an empty value gave before.
    for args, option in [(["spmv", "--json", ""], "json"), (["spmv", "--readme", ""], "readme"),
                         (["record-all", "--out", ""], "out")]:
        r.run(f"lessons: {args[0]} --{option} ''", [str(r.build / "fem_lessons"), *args],
              "refuse", f"--{option}: an empty value")
    r.run("lessons: phase-owners --write ''",
          [str(r.build / "fem_lessons"), "phase-owners", "--write", ""], "refuse",
          r"--write: an empty value")


def meshes(r):
    def sim_mesh(name, text, expect, pattern=""):
        r.run("mesh: " + name, r.sim("--mesh", r.mesh(name.replace(" ", "_")[:60] + ".msh",
                                                      text)), expect, pattern)

    plane = [(x, y, 1.0 - x - y) for (x, y, _) in CORNERS]  # all on x + y + z = 1
    sim_mesh("the cube (control)", msh22(), "ok", r"8 nodes, 6 tets")
    sim_mesh("tets coplanar on a tilted plane", msh22(points=plane), "refuse", r"degenerate")
    sim_mesh("$PhysicalNames only", "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$PhysicalNames\n"
             "1\n3 1 \"body\"\n$EndPhysicalNames\n", "refuse", r"\$Nodes")
    sim_mesh("$PhysicalNames then the cube", msh22(extra_before="$PhysicalNames\n1\n3 1 "
                                                   "\"body\"\n$EndPhysicalNames\n"), "ok")
    sim_mesh("$PhysicalNames twice", msh22(extra_before="$PhysicalNames\n0\n$EndPhysicalNames\n"
                                           "$PhysicalNames\n0\n$EndPhysicalNames\n"), "ok")
    # gmsh reads these three as it reads any file: a header read twice, lines outside the
    # sections and the data size skipped (ASCII numbers carry their own size).
    sim_mesh("$MeshFormat twice", msh22(extra_before="$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"),
             "ok", r"6 tets")
    sim_mesh("a $Comments section", msh22(extra_before="$Comments\nmade by hand\n$EndComments\n"),
             "ok")
    sim_mesh("a $NodeData section after the mesh", msh22(
        extra_after="$NodeData\n1\n\"u\"\n1\n0.0\n3\n0\n1\n8\n" +
        "".join(f"{i + 1} 0\n" for i in range(8)) + "$EndNodeData\n"), "ok")
    sim_mesh("tabs between the numbers", msh22(sep="\t"), "ok", r"8 nodes, 6 tets")
    sim_mesh("several spaces between the numbers", msh22(sep="   "), "ok", r"8 nodes, 6 tets")
    sim_mesh("trailing text lines after $EndElements", msh22(extra_after="garbage\nmore\n"),
             "ok", r"6 tets")
    sim_mesh("binary flag in a 2.2 header", msh22(header="2.2 1 8"), "refuse", r"binary")
    sim_mesh("data size 4 in a 2.2 header", msh22(header="2.2 0 4"), "ok", r"6 tets")
    sim_mesh("version 2.20", msh22(header="2.20 0 8"), "ok")
    sim_mesh("version 4.10", msh22(header="4.10 0 8"), "refuse", r".")
    sim_mesh("node tags starting at 100", msh22(first_tag=100), "ok", r"8 nodes, 6 tets")
    sim_mesh("zero tets, two lines", msh22(element_lines=["1 1 2 1 1 1 2", "2 1 2 1 1 2 3"]),
             "refuse", r"no tetrahedra")
    sim_mesh("zero elements at all", msh22(element_lines=[]), "refuse", r"no tetrahedra")
    sim_mesh("elements without tags (0 tags)", msh22(elem_tags="0"), "ok", r"6 tets")
    sim_mesh("a node in no tetrahedron", msh22(points=CORNERS + [(5.0, 5.0, 5.0)]), "ok",
             r"8 nodes|9 nodes|no tetrahedron")
    sim_mesh("every tet inverted", msh22(tets=[(a, c, b, d) for a, b, c, d in TETS]), "ok",
             r"6 tets")
    sim_mesh("Fortran D exponents", msh22(node_lines=[
        f"{i + 1} {p[0]}.0D0 {p[1]}.0D0 {p[2]}.0D0" for i, p in enumerate(CORNERS)]), "refuse",
        r"line|node")
    sim_mesh("a node line with four coordinates", msh22(node_lines=[
        f"{i + 1} {p[0]} {p[1]} {p[2]} 7" for i, p in enumerate(CORNERS)]), "refuse", r"node")
    sim_mesh("a fractional node tag", msh22(node_lines=[
        f"{i + 1}.5 {p[0]} {p[1]} {p[2]}" for i, p in enumerate(CORNERS)]), "refuse", r"node")
    sim_mesh("blank lines between sections", msh22().replace("$EndNodes\n", "$EndNodes\n\n\n"),
             "ok")
    sim_mesh("leading spaces before $MeshFormat", "  " + msh22(), "refuse", r"MeshFormat")
    sim_mesh("lower-case $meshformat", msh22().replace("$MeshFormat", "$meshformat", 1),
             "refuse", r"MeshFormat")
    sim_mesh("no $EndMeshFormat", msh22().replace("$EndMeshFormat\n", ""), "refuse", r".")
    sim_mesh("an element count of 1e20 digits", msh22().replace("$Elements\n6", "$Elements\n" +
                                                                "9" * 20), "refuse",
             r"line 16: '9+' is not the section's header")
    sim_mesh("a NUL byte inside a node line",
             msh22().encode().replace(b"2 1.0 0.0", b"2 1.0\x000.0", 1), "refuse", r"line|node")
    sim_mesh("UTF-16 with a BOM", msh22().encode("utf-16"), "refuse", r"byte-order|MeshFormat")
    sim_mesh("CRLF everywhere", msh22().replace("\n", "\r\n"), "ok", r"6 tets")
    sim_mesh("no newline at the end", msh22().rstrip("\n"), "ok", r"6 tets")
    # Read right, as the count and the numbers are there (gmsh's fscanf takes hexadecimal too).
    sim_mesh("a node count with trailing text", msh22().replace("$Nodes\n8\n", "$Nodes\n8 junk\n"),
             "ok", r"8 nodes, 6 tets")
    sim_mesh("an element naming a node tag past the last", msh22(element_lines=[
        "1 4 2 1 1 1 2 4 99"]), "refuse", r"99")
    sim_mesh("a node tag of 2^31", msh22(first_tag=2 ** 31), "ok", r"8 nodes, 6 tets")
    sim_mesh("exponent-only coordinates (1e0)", msh22(node_lines=[
        f"{i + 1} {p[0]}e0 {p[1]}e0 {p[2]}e0" for i, p in enumerate(CORNERS)]), "ok", r"6 tets")
    sim_mesh("hexadecimal coordinates", msh22(node_lines=[
        f"{i + 1} 0x{p[0]}p0 0x{p[1]}p0 0x{p[2]}p0" for i, p in enumerate(CORNERS)]), "ok",
        r"8 nodes, 6 tets")
    sim_mesh("a NaN spelled nan(0x1)", msh22(node_lines=[
        f"{i + 1} {'nan(0x1)' if i == 3 else p[0]} {p[1]} {p[2]}" for i, p in enumerate(CORNERS)]),
        "refuse", r"NaN|node|line")
    sim_mesh("4.1 cube (control)", msh41(), "ok", r"8 nodes, 6 tets")
    sim_mesh("4.1 node block declaring 1e9 nodes", msh41(node_block_count=10 ** 9), "refuse",
             r"a node block of 1000000000 nodes where the header's 8 leave 8")
    sim_mesh("4.1 element block declaring 1e9 elements", msh41(elem_block_count=10 ** 9),
             "refuse", r"an element block of 1000000000 elements")
    sim_mesh("4.1 negative element block count", msh41(elem_block_count=-3), "refuse",
             r"Elements|negative")
    sim_mesh("4.1 parametric node block (u v w after x y z)", msh41(parametric=1), "ok",
             r"8 nodes, 6 tets")
    sim_mesh("4.1 node tags from 100", msh41(first_tag=100), "ok", r"8 nodes, 6 tets")
    sim_mesh("4.1 coplanar tets", msh41(points=plane), "refuse", r"degenerate")
    sim_mesh("4.1 with an empty $Entities", msh41().replace(
        "$EndMeshFormat\n", "$EndMeshFormat\n$Entities\n0 0 0 0\n$EndEntities\n"), "ok")
    sim_mesh("4.1 with a huge $Entities count", msh41().replace(
        "$EndMeshFormat\n", "$EndMeshFormat\n$Entities\n999999999 0 0 0\n$EndEntities\n"), "refuse",
             r"\$Entities section declares 999999999 entities")


def environment(r):
    beam = str(BEAM)
    # A value in the one form both OpenMP runtimes read alike is a count asked for; any other is
    # refused before OpenMP starts, --threads given or not (LLVM's libomp aborts on "+2", "1.5",
    # "2abc", "" or 20 nines; libgomp ignored them and ran its default, which must not pass for
    # the user's count either).
    asked2 = r"threads: 2 \(asked"
    not_a_count = r"is not a thread count"
    for value, expect, pattern in [(" 2", "ok", asked2), ("02", "ok", asked2),
                                   (" 2 ", "ok", asked2), ("1,1,1", "ok", r"threads: 1 \(asked"),
                                   ("+2", "refuse", not_a_count), ("9" * 20, "refuse", not_a_count),
                                   ("1.5", "refuse", not_a_count), ("２", "refuse", not_a_count),
                                   ("2abc", "refuse", not_a_count), ("2,", "refuse", not_a_count),
                                   ("", "refuse", not_a_count), ("abc", "refuse", not_a_count),
                                   ("100000", "refuse", r"OMP_NUM_THREADS=100000")]:
        r.run(f"env: OMP_NUM_THREADS={value!r}", r.sim("--mesh", beam), expect, pattern,
              env={"OMP_NUM_THREADS": value})
    r.run("env: OMP_NUM_THREADS='1.5' with --threads 2", r.sim("--mesh", beam, "--threads", "2"),
          "refuse", not_a_count, env={"OMP_NUM_THREADS": "1.5"})
    for value in ["", "0", "1", "garbage"]:
        r.run(f"env: FEM_ADAPTIVE_TEAM={value!r}, chapter 09 at 2 threads",
              r.sim("--mesh", beam, "--chapter", "09", "--threads", "2"), "ok",
              env={"FEM_ADAPTIVE_TEAM": value})
    r.run("env: FEM_FAIL_WRITES='' (no file of that name)",
          r.sim("--mesh", beam, "--every", "1", "--out", "fw"), "ok",
          env={"FEM_FAIL_WRITES": ""})
    r.run("env: FEM_FAIL_WRITES='*' fails the frames, said",
          r.sim("--mesh", beam, "--every", "1", "--out", "fw2"), "refuse", r"cannot|write",
          env={"FEM_FAIL_WRITES": "*"})
    r.run("env: LC_ALL=de_DE.UTF-8 (comma decimals) reads the mesh's dots",
          r.sim("--mesh", beam, "--E", "1e5"), "ok", r"515 nodes", env={"LC_ALL": "de_DE.UTF-8"})


def standard_output(r):
    # The printed result (a watched node, a table, the help) lost to a full disk or a closed
    # stream: the exit status says so, as a shell pipeline's next command needs.
    beam = str(BEAM)
    lessons = str(r.build / "fem_lessons")
    for target in ("/dev/full", "closed"):
        r.run(f"stdout {target}: fem_sim --watch", r.sim("--mesh", beam, "--watch", "3"),
              "refuse", r"cannot write the standard output", stdout=target)
        r.run(f"stdout {target}: fem_sim --help", [str(r.build / "fem_sim"), "--help"],
              "refuse", r"cannot write the standard output", stdout=target)
        r.run(f"stdout {target}: fem_lessons phase-owners", [lessons, "phase-owners"],
              "refuse", r"cannot write the standard output", stdout=target)
    for program in ("fem_bench", "fem_viewer", "fem_lessons"):
        r.run(f"stdout /dev/full: {program} --help", [str(r.build / program), "--help"],
              "refuse", r"cannot write the standard output", stdout="/dev/full")
    r.run("stdout /dev/full: a refused option keeps its own status 2",
          r.sim("--mesh", beam, "--E", "0"), "refuse", r"E must be positive", stdout="/dev/full")
    # A closed standard output is not a free number for the program's files to take: fem_bench
    # holds its run folder's lock file open while it prints its tables, and printed them into it
    # (then deleted it, exit status 0: the tables lost, silently).
    r.run("stdout closed: fem_bench printing while its run's lock file is open",
          [str(r.build / "fem_bench"), "--mesh", beam, "--chapters", "01", "--steps", "2",
           "--out", "bench_closed"], "refuse", r"cannot write the standard output",
          stdout="closed")


def main():
    r = Runner(sys.argv[1])
    for group in (sim_options, viewer_options, bench_options, meshes, environment,
                  standard_output):
        group(r)
    failed = [(n, d) for n, ok, d in r.results if not ok]
    for name, detail in failed:
        print(f"WRONG: {name}: {detail}")
    for name, why in r.known:
        print(f"KNOWN WRONG, NOT TRIED: {name}: {why}")
    print(f"{len(r.results)} inputs tried, {len(r.results) - len(failed)} right, "
          f"{len(failed)} wrong, {len(r.known)} known wrong and not tried")
    if not failed:
        print("PASS: every new input is refused with its cause or runs right")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
