"""Checks that the compiler vectorized every `#pragma omp simd` loop of a source file.

Compiles the file as the build does (its command from compile_commands.json, with the
build's -march=native) plus GCC's vectorization report (-fopt-info-vec-all), and fails when
a loop marked `#pragma omp simd` is reported as not vectorized with no report that it was.
A loop the compiler turned into something else (a memcpy, say) has neither report and
passes. GCC only: Clang unrolls these 8-iteration loops before its loop vectorizer runs and
vectorizes the unrolled code (SLP), so its remarks name no loop (and Clang warns by itself,
-Wpass-failed, when it cannot honour `omp simd`).

Why a test: whether a loop vectorizes depends on the instruction set. Chapter 12's Newton
loop vectorized on an AVX-512 machine and stayed scalar on an AVX2 one (GCC sank arithmetic
into a select's arm, which -ftrapping-math forbids to run for every lane unless AVX-512's
masks can hide it), and nothing but a report says so.

What each instruction set can vectorize: a loop that stores a select's result into memory that
its other arm reads (`a[l] = c ? b[l] : a[l]`) stays a branch unless the target has masked
stores (GCC writes only the lanes whose condition holds: another thread may own the others).
AVX, AVX2, AVX-512 and SVE have them; SSE (the x86-64 baseline) and NEON (every ARM64 core, Apple
Silicon's included) do not. On a target without them such a loop, reported not vectorized for
its control flow, is named as scalar for want of masked stores and does not fail the check.
At the x86-64 baseline (SSE2) GCC 12 also finds no vector type for the loops that mix doubles
with 64-bit integer flags, which it vectorizes from x86-64-v2 on: named too. Every other loop
must vectorize on every target.

"""
import json
import re
import shlex
import subprocess
import sys
import tempfile
from pathlib import Path

from femtools.args import command_parser


def simd_loops(lines):
    """(first line, last line) of each loop after a `#pragma omp simd`, 1-based."""
    loops = []
    for index, line in enumerate(lines):
        if not line.strip().startswith("#pragma omp simd"):
            continue
        start = index + 1
        depth, end, opened = 0, start, False
        for k in range(start, len(lines)):
            text = lines[k].split("//")[0]
            for ch in text:
                if ch in "({":
                    depth += 1
                    opened = opened or ch == "{"
                elif ch in ")}":
                    depth -= 1
            end = k
            # The loop ends where its braces close, or, without braces, at its statement's ';'.
            if depth == 0 and (opened or text.rstrip().endswith(";")):
                break
        loops.append((start + 1, end + 1))
    return loops


# The instruction sets, widest first: (predefined macro, name, has masked stores).
INSTRUCTION_SETS = [
    ("__AVX512F__", "AVX-512", True),
    ("__AVX2__", "AVX2", True),
    ("__AVX__", "AVX", True),
    ("__ARM_FEATURE_SVE", "SVE", True),
    ("__ARM_NEON", "NEON", False),
    ("__SSE4_2__", "SSE4.2", False),
    ("__SSE2__", "SSE2", False),
]


def instruction_set(args):
    """(name, has masked stores) of the target the compile command builds for."""
    flags = [a for a in args[1:] if a.startswith(("-m", "-f", "-O", "-std", "--target"))]
    run = subprocess.run(
        [args[0], *flags, "-dM", "-E", "-x", "c++", "/dev/null"], capture_output=True, text=True
    )
    macros = set(re.findall(r"#define (\w+)", run.stdout))
    for macro, name, masked in INSTRUCTION_SETS:
        if macro in macros:
            return name, masked
    return "this target", False


def conditional_store(lines, first, last):
    """Whether the loop stores a select's result (`x = c ? y : z`), which needs masked stores."""
    body = " ".join(line.split("//")[0] for line in lines[first - 1 : last])
    return re.search(r"[^=!<>]=[^=][^;]*\?[^;]*:", body) is not None


def lacks(isa, masked_stores, reasons, stores_select):
    """What the instruction set lacks that keeps a loop scalar (None: nothing known, a failure)."""
    if not masked_stores and stores_select and any("control flow" in r for r in reasons):
        return (
            "its conditional stores need masked stores (AVX, AVX2, AVX-512, SVE), "
            f"which {isa} lacks"
        )
    if isa == "SSE2" and any("no vectype" in r for r in reasons):
        # GCC 12 vectorizes these loops from x86-64-v2 (SSE4.2) on: checked by compiling
        # batch_rotations.cpp at -march=x86-64 and -march=x86-64-v2.
        return (
            "GCC finds no SSE2 vector type for its mix of doubles and 64-bit integer flags "
            "(it vectorizes it from x86-64-v2, SSE4.2, on)"
        )
    return None


def report(build_dir: Path, source: Path):
    commands = json.loads((build_dir / "compile_commands.json").read_text())
    entry = next((c for c in commands if Path(c["file"]).resolve() == source.resolve()), None)
    if entry is None:
        sys.exit(f"fem-tools check vectorized: {source} is not in {build_dir}/compile_commands.json")
    args = entry["arguments"] if "arguments" in entry else shlex.split(entry["command"])
    if "-o" in args:
        out = args.index("-o")
        del args[out : out + 2]
    compiler = args[0]
    version = subprocess.run([compiler, "--version"], capture_output=True, text=True).stdout
    if "Free Software Foundation" not in version or "clang" in version.lower():
        sys.exit(f"fem-tools check vectorized: {compiler} is not GCC; this check reads GCC's report")
    with tempfile.TemporaryDirectory() as tmp:
        run = subprocess.run(
            args + ["-fopt-info-vec-all", "-o", str(Path(tmp) / "out.o")],
            cwd=entry["directory"],
            capture_output=True,
            text=True,
        )
    if run.returncode != 0:
        sys.exit(f"check_vectorized: the compile failed:\n{run.stderr[-3000:]}")
    isa = instruction_set(args)
    done, missed = set(), {}
    name = re.escape(source.name)
    for line in run.stderr.splitlines():
        found = re.search(name + r":(\d+):\d+: (.*)", line)
        if not found:
            continue
        number, text = int(found.group(1)), found.group(2)
        if "loop vectorized" in text:
            done.add(number)
        elif "missed:" in text and "not vectorized" in text or "couldn't vectorize loop" in text:
            missed.setdefault(number, []).append(text)
    return done, missed, isa


def main(argv=None, prog=None):
    parser = command_parser(prog, __doc__)
    parser.add_argument("build_dir", type=Path, help="the build folder (its compile_commands.json)")
    parser.add_argument("source", type=Path, help="the source file whose loops are checked")
    args = parser.parse_args(argv)
    build_dir, source = args.build_dir, args.source
    lines = source.read_text().splitlines()
    loops = simd_loops(lines)
    if not loops:
        sys.exit(f"check_vectorized: {source} has no `#pragma omp simd` loop")
    done, missed, (isa, masked_stores) = report(build_dir, source)
    if not done:
        # Not one loop of the file reported vectorized: the report was not read (another
        # format, or no optimization), and silence would pass every loop.
        sys.exit(f"check_vectorized: GCC reported no vectorized loop in {source.name}")
    failed = scalar = 0
    for first, last in loops:
        inside = range(first, last + 1)
        if any(n in done for n in inside):
            continue
        reasons = [text for n in inside for text in missed.get(n, [])]
        if not reasons:
            continue
        why = lacks(isa, masked_stores, reasons, conditional_store(lines, first, last))
        if why:
            scalar += 1
            print(f"{source.name}:{first}: scalar on {isa}: {why}: {lines[first - 1].strip()}")
            continue
        failed += 1
        print(f"{source.name}:{first}: not vectorized on {isa}: {lines[first - 1].strip()}")
        for reason in reasons:
            print(f"    {reason}")
    vectorized = sum(1 for first, last in loops if any(n in done for n in range(first, last + 1)))
    print(
        f"{source.name} on {isa}: {len(loops)} `#pragma omp simd` loops, {vectorized} reported "
        f"vectorized, {scalar} scalar for what {isa} lacks, {failed} reported not vectorized"
    )
    return 1 if failed else 0
