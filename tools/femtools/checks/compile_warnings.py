"""Zero warnings on any x86-64 machine that -march=native may select: configures one build
per target level (FEM_NATIVE=OFF, CMAKE_CXX_FLAGS=-march=x86-64-vN) and compiles every source
with its real command (-O3 -c: some warnings, such as GCC 12's inside avx512fintrin.h, come
from the optimizer, so a syntax check would miss them). Compiles only (ninja builds the object
files, nothing is linked), so the host needs none of the instruction sets. The compilations go
through the build's compiler launcher (ccache, CMakeLists.txt), which replays a cached
compilation's warnings: a file compiled the same way before, by another build folder at the same
depth (CI's clang preset at x86-64-v3), is checked without compiling it again. Exits 1 on any
"warning:".

    fem-tools check warnings                     # x86-64-v3 and x86-64-v4
    fem-tools check warnings --march x86-64-v4 --jobs 2
    fem-tools check warnings --cxx clang++       # the same for Clang

The default compiler is CMake's (GCC on Debian); with --cxx the build folders are named after
it (build/march-clang++-x86-64-v3), so the two never share a CMake cache.
"""
import json
import os
import pathlib
import shlex
import subprocess
import time

from femtools.args import command_parser
from femtools.paths import ROOT


def configure(march, build_dir, cxx=None):
    compiler = [f"-DCMAKE_CXX_COMPILER={cxx}"] if cxx else []
    subprocess.run(["cmake", "-S", str(ROOT), "-B", str(build_dir), "-G", "Ninja",
                    "-DCMAKE_BUILD_TYPE=Release", "-DFEM_NATIVE=OFF",
                    f"-DCMAKE_CXX_FLAGS=-march={march}", *compiler],
                   check=True, stdout=subprocess.DEVNULL)
    return json.loads((build_dir / "compile_commands.json").read_text())


def object_file(entry, build_dir):
    """The object file a compile_commands.json entry writes, as ninja names it."""
    command = entry.get("arguments") or shlex.split(entry["command"])
    out = pathlib.Path(entry["directory"]) / command[command.index("-o") + 1]
    return out.relative_to(build_dir)


def compile_objects(build_dir, objects, jobs):
    """Builds the object files anew (removed first, so ninja runs every compilation, which ccache
    may serve with its recorded output); returns (warnings, failed compilations)."""
    for obj in objects:
        (build_dir / obj).unlink(missing_ok=True)
    p = subprocess.Popen(["ninja", "-C", str(build_dir), "-j", str(jobs), "-k", "0",
                          *map(str, objects)], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                         text=True)
    warnings = failed = 0
    for line in p.stdout:
        print(line, end="", flush=True)
        warnings += line.count("warning:")
        failed += line.startswith("FAILED:")
    p.wait()
    return warnings, failed + (p.returncode != 0 and not failed)


def main(argv=None, prog=None):
    parser = command_parser(prog, __doc__)
    parser.add_argument("--march", action="append", help="target level (repeatable); "
                        "default x86-64-v3 and x86-64-v4")
    parser.add_argument("--build-root", type=pathlib.Path, default=ROOT / "build")
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    parser.add_argument("--cxx", help="the C++ compiler (default: CMake's choice, GCC on Debian)")
    args = parser.parse_args(argv)
    failed = False
    for march in args.march or ["x86-64-v3", "x86-64-v4"]:
        name = f"march-{march}" if not args.cxx else f"march-{pathlib.Path(args.cxx).name}-{march}"
        build_dir = (args.build_root / name).resolve()
        objects = [object_file(e, build_dir) for e in configure(march, build_dir, args.cxx)
                   if pathlib.Path(e["file"]).exists()]
        print(f"{args.cxx or 'c++'} -march={march}: compiling {len(objects)} sources in {build_dir} "
              f"({args.jobs} at a time)", flush=True)
        start = time.monotonic()
        warnings, errors = compile_objects(build_dir, objects, args.jobs)
        print(f"{args.cxx or 'c++'} -march={march}: {warnings} warnings, {errors} failed compilations "
              f"({time.monotonic() - start:.0f} s)")
        failed |= warnings > 0 or errors > 0
    return 1 if failed else 0
