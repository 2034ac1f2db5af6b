#!/usr/bin/env python3
"""Zero warnings on any x86-64 machine that -march=native may select: configures one build
per target level (FEM_NATIVE=OFF, CMAKE_CXX_FLAGS=-march=x86-64-vN) and compiles every source
with its real command from compile_commands.json (-O3 -c: some warnings, such as GCC 12's
inside avx512fintrin.h, come from the optimizer, so a syntax check would miss them). Compiles
only, so the host needs none of the instruction sets. Exits 1 on any "warning:".

    .venv/bin/python scripts/check_warnings.py                     # x86-64-v3 and x86-64-v4
    .venv/bin/python scripts/check_warnings.py --march x86-64-v4 --jobs 2
    .venv/bin/python scripts/check_warnings.py --cxx clang++       # the same for Clang

The default compiler is CMake's (GCC on Debian); with --cxx the build folders are named after
it (build/march-clang++-x86-64-v3), so the two never share a CMake cache.
"""
import argparse
import concurrent.futures
import json
import os
import pathlib
import shlex
import subprocess
import sys
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent


def configure(march, build_dir, cxx=None):
    compiler = [f"-DCMAKE_CXX_COMPILER={cxx}"] if cxx else []
    subprocess.run(["cmake", "-S", str(ROOT), "-B", str(build_dir), "-G", "Ninja",
                    "-DCMAKE_BUILD_TYPE=Release", "-DFEM_NATIVE=OFF",
                    f"-DCMAKE_CXX_FLAGS=-march={march}", *compiler],
                   check=True, stdout=subprocess.DEVNULL)
    return json.loads((build_dir / "compile_commands.json").read_text())


def compile_one(entry):
    """Compiles one source with its own command; returns (file, seconds, output)."""
    command = entry.get("arguments") or shlex.split(entry["command"])
    out = pathlib.Path(entry["directory"]) / command[command.index("-o") + 1]
    out.parent.mkdir(parents=True, exist_ok=True)
    start = time.monotonic()
    p = subprocess.run(command, cwd=entry["directory"], capture_output=True, text=True)
    return entry["file"], time.monotonic() - start, p.stdout + p.stderr, p.returncode


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--march", action="append", help="target level (repeatable); "
                        "default x86-64-v3 and x86-64-v4")
    parser.add_argument("--build-root", type=pathlib.Path, default=ROOT / "build")
    parser.add_argument("--jobs", type=int, default=min(2, os.cpu_count() or 1))
    parser.add_argument("--cxx", help="the C++ compiler (default: CMake's choice, GCC on Debian)")
    args = parser.parse_args()
    failed = False
    for march in args.march or ["x86-64-v3", "x86-64-v4"]:
        name = f"march-{march}" if not args.cxx else f"march-{pathlib.Path(args.cxx).name}-{march}"
        build_dir = args.build_root / name
        entries = [e for e in configure(march, build_dir, args.cxx)
                   if pathlib.Path(e["file"]).exists()]
        print(f"{args.cxx or 'c++'} -march={march}: compiling {len(entries)} sources in {build_dir} "
              f"({args.jobs} at a time)", flush=True)
        warnings = errors = 0
        with concurrent.futures.ThreadPoolExecutor(args.jobs) as pool:
            for k, (source, seconds, output, rc) in enumerate(pool.map(compile_one, entries), 1):
                count = output.count("warning:")
                warnings += count
                errors += rc != 0
                rel = pathlib.Path(source).resolve().relative_to(ROOT)
                print(f"  [{k}/{len(entries)}] {rel}: {seconds:.0f} s"
                      f"{f', {count} warnings' if count else ''}{', FAILED' if rc else ''}", flush=True)
                if count or rc:
                    print(output[:4000])
        print(f"{args.cxx or 'c++'} -march={march}: {warnings} warnings, {errors} failed compilations")
        failed |= warnings > 0 or errors > 0
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
