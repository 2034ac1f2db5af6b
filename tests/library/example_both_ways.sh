#!/usr/bin/env bash
# The library's example (examples/beam) as another project builds it, both ways:
#   1. against this build installed into a temporary prefix (find_package),
#   2. with the repository added as a subdirectory (add_subdirectory),
# each with zero warnings at -Wall -Wextra -Wpedantic, and each run's tip deflection equal to
# fem_sim's on the same body (the mesh the example writes, its E and steps) within 1e-12; and
# examples/interactive against the installed package, running to its PASS.
# Usage: example_both_ways.sh BUILD_DIR FEM_SIM WORK_DIR [WAYS]
# WAYS: "installed subdirectory" (the default, CI's part) or one of them. The ctest test runs
# the installed way only: the subdirectory way compiles the library once more (ccache cannot
# serve it: the object files' paths differ), minutes that the suite should not wait for.
set -euo pipefail
build=$1 fem_sim=$2 work=$(realpath -m "$3") ways=${4:-installed subdirectory}
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
rm -rf "$work"
mkdir -p "$work"
# The repository's files compile as in the main build (same flags, paths made relative to the
# repository by ccache), so the subdirectory build is served from the cache.
launcher=()
if command -v ccache >/dev/null; then
  launcher=("-DCMAKE_CXX_COMPILER_LAUNCHER=cmake;-E;env;CCACHE_BASEDIR=$repo;CCACHE_NOHASHDIR=1;ccache")
fi

cmake --install "$build" --prefix "$work/prefix" >"$work/install.log"
test -f "$work/prefix/lib/cmake/femcourse/femcourse-config-version.cmake"
# The package holds no gmsh, Catch2 nor Python, and names no file of this source tree.
if grep -rqiE "gmsh|catch2|python|$repo" "$work/prefix/lib/cmake/femcourse/femcourse-targets"*.cmake; then
  echo "FAIL: the installed package's targets name gmsh, Catch2, Python or the source tree" >&2
  exit 1
fi

# The consumer compiles with the build's own compiler: a library built by Clang calls Clang's
# OpenMP runtime (libomp), which GCC's OpenMP::OpenMP_CXX (libgomp) does not provide.
compiler=$(sed -n 's/^CMAKE_CXX_COMPILER:[A-Z]*=//p' "$build/CMakeCache.txt")

build_example() {  # NAME CMAKE_ARGS...
  local name=$1
  shift
  cmake -S "$repo/examples/beam" -B "$work/$name" -G Ninja -DCMAKE_BUILD_TYPE=Release \
    ${compiler:+"-DCMAKE_CXX_COMPILER=$compiler"} "${launcher[@]}" "$@" >"$work/$name.configure.log"
  cmake --build "$work/$name" 2>&1 | tee "$work/$name.build.log" | tail -n 1
  if grep -q "warning:" "$work/$name.build.log"; then
    grep -B2 -A6 "warning:" "$work/$name.build.log" | head -n 40 >&2
    echo "FAIL: warnings in the $name build" >&2
    exit 1
  fi
}

# Prints the example's deflection and fem_sim's on the mesh the example wrote; fails unless
# they agree within 1e-12.
compare() {  # NAME
  local out node steps deflection z
  out=$("$work/$1/beam" --msh "$work/$1.msh")
  echo "$1: $out"
  node=$(sed -n 's/.*tip node \([0-9]*\) deflection.*/\1/p' <<<"$out")
  steps=$(sed -n 's/.*, \([0-9]*\) steps:.*/\1/p' <<<"$out")
  deflection=$(sed -n 's/.* deflection \([-0-9.e+]*\) m.*/\1/p' <<<"$out")
  # E = 1e6 Pa and the beam's height H = 0.1 m, as beam.cpp sets them; the rest are defaults.
  z=$("$fem_sim" --mesh "$work/$1.msh" --E 1e6 --steps "$steps" --every 0 --watch "$node" |
    sed -n "s/^node $node at [^ ]* [^ ]* \(.*\)$/\1/p")
  echo "$1: fem_sim's node $node ends at z = $z"
  awk -v a="$deflection" -v z="$z" 'BEGIN {
    d = a - (z - 0.1); if (d < 0) d = -d
    printf "%s: |example - fem_sim| = %.3g\n", "'"$1"'", d
    exit !(a != "" && z != "" && d <= 1e-12) }'
}

for way in $ways; do
  case $way in
    installed) build_example installed "-DCMAKE_PREFIX_PATH=$work/prefix" ;;
    # The library compiles for the instruction set of the build it is compared with (a
    # subdirectory is portable by default; another -march rounds differently, ~1e-11 m here).
    subdirectory) build_example subdirectory "-DFEMCOURSE_SOURCE_DIR=$repo" \
      "-DFEM_NATIVE=$(sed -n 's/^FEM_NATIVE:BOOL=//p' "$build/CMakeCache.txt")" ;;
    *) echo "unknown way '$way' (installed, subdirectory)" >&2 && exit 2 ;;
  esac
  compare "$way"
done
# The interactive example (examples/interactive: floor, grab, drag, release, surface, forces)
# against the installed package: it checks its own story and prints PASS. (Its subdirectory
# way compiles the library once more for the same CMake code the beam's way tests.)
if [[ " $ways " == *" installed "* ]]; then
  cmake -S "$repo/examples/interactive" -B "$work/interactive" -G Ninja -DCMAKE_BUILD_TYPE=Release \
    ${compiler:+"-DCMAKE_CXX_COMPILER=$compiler"} "${launcher[@]}" "-DCMAKE_PREFIX_PATH=$work/prefix" \
    >"$work/interactive.configure.log"
  cmake --build "$work/interactive" 2>&1 | tee "$work/interactive.build.log" | tail -n 1
  if grep -q "warning:" "$work/interactive.build.log"; then
    echo "FAIL: warnings in the interactive example's build" >&2
    exit 1
  fi
  "$work/interactive/interactive" | tee "$work/interactive.log"
  grep -q "^PASS" "$work/interactive.log"
fi
if [[ " $ways " == *" subdirectory "* ]]; then
  # The subdirectory build made the library alone: no tests, no programs.
  test ! -e "$work/subdirectory/femcourse/fem_sim"
  test ! -e "$work/subdirectory/femcourse/tests"
fi
echo "PASS: the example builds ($ways) and agrees with fem_sim"
