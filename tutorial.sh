#!/usr/bin/env bash
# One entry point for the tutorial: set-up, build, tests, benchmark, simulation.
# Every subcommand sets up what is missing first (idempotent), so a fresh clone of the
# repository on Debian 12 needs nothing but this script.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
cd "$ROOT"
PRESET="${PRESET:-release}"           # release | debug | asan
BUILD_DIR="$ROOT/build/$PRESET"
VENV="$ROOT/.venv"

APT_PACKAGES=(
  build-essential cmake ninja-build git python3 python3-venv
  libeigen3-dev catch2
  # gmsh's runtime libraries (the PyPI wheel links against them)
  libglu1-mesa libgl1 libxrender1 libxcursor1 libxft2 libxinerama1 libfontconfig1 libgomp1
  # the viewer: GLFW, OpenGL, Dear ImGui (with its GLFW and OpenGL 3 backends), stb for the
  # screenshots; Xvfb and Mesa's software renderer run it headless in the tests
  pkg-config libglfw3-dev libgl-dev libimgui-dev libstb-dev xvfb xauth libgl1-mesa-dri
)

usage() {
  cat <<USAGE
usage: ./tutorial.sh <command> [arguments passed to the program]

commands:
  setup      install what is missing (Debian packages, .venv with requirements.txt), configure, build
  build      set up if needed and build (preset: \$PRESET, default release)
  test       build and run every test through ctest (ctest arguments may follow, e.g. -L ch01)
  bench      build and benchmark every chapter on the poster-sized mesh:
             prints the per-phase table, writes results/bench.json (and plots when present)
  scaling    build and run the chapters over the beam series up to about 100,000 nodes (large
             meshes generated on demand), with a time budget per run: results/scaling.json and
             results/scaling.png
  threads    build and measure chapter 09 (and 08 beside it) at 1, 2, ... up to every hardware
             thread on the poster-sized mesh: results/threads.json and results/threads.png
             (step and solve time against threads, with the ideal line)
  docs       regenerate the generated parts of the docs from results/ (tables in docs/results.md,
             the README and the chapter READMEs, plots copied to docs/images/), the lesson
             tables (fem_lessons), the chapter diffs (docs/diffs/) and the viewer's screenshot
             (docs/images/viewer.png, headless); run bench first (scaling and viewer-bench
             too, for their tables: without their results the committed tables stay)
  sim        build and run the cantilever on the poster-sized mesh (VTK frames in out/sim/, open
             out/sim/cantilever.pvd in ParaView) and render them to docs/images/cantilever.gif
  viewer-bench
             build and measure the viewer's frame rate per chapter on the poster-sized mesh,
             headless (Xvfb): results/viewer.json, shown in the README by docs
  viewer     build and open the interactive viewer (fem_viewer --help for its options): drag the
             body with the mouse, switch chapters live; needs a display
  meshes     regenerate the committed meshes with gmsh (meshes/generate.py)
  help       this text (also --help, -h)

environment:
  PRESET=release|debug|asan   which CMake preset to build and test with (default release)
USAGE
}

log() { printf '\033[1m==> %s\033[0m\n' "$*"; }

missing_packages() {
  local p
  for p in "${APT_PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || echo "$p"
  done
}

install_system_packages() {
  local missing
  missing=$(missing_packages | tr '\n' ' ')
  [ -z "${missing// /}" ] && return 0
  if [ "$(id -u)" -eq 0 ]; then
    log "installing Debian packages: $missing"
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq
    # shellcheck disable=SC2086
    apt-get install -y -qq --no-install-recommends $missing
  else
    echo "Missing Debian packages. Please run:" >&2
    echo "  sudo apt-get install -y $missing" >&2
    echo "then run ./tutorial.sh again." >&2
    exit 1
  fi
}

setup_venv() {
  local stamp="$VENV/.requirements.sha256"
  local want
  want=$(sha256sum requirements.txt | cut -d' ' -f1)
  if [ -x "$VENV/bin/python" ] && [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$want" ]; then
    return 0
  fi
  log "creating .venv and installing requirements.txt (gmsh, matplotlib)"
  [ -x "$VENV/bin/python" ] || python3 -m venv "$VENV"
  "$VENV/bin/python" -m pip install --quiet --disable-pip-version-check -r requirements.txt
  echo "$want" >"$stamp"
}

configure() {
  if [ ! -f "$BUILD_DIR/CMakeCache.txt" ]; then
    log "configuring (preset $PRESET)"
    cmake --preset "$PRESET"
  fi
}

setup() {
  install_system_packages
  setup_venv
  configure
}

build() {
  setup
  log "building (preset $PRESET)"
  cmake --build --preset "$PRESET"
}

run_tests() {
  build
  log "running the tests"
  ctest --preset "$PRESET" -j "$(nproc)" "$@"
}

bench() {
  build
  mkdir -p results
  log "benchmarking every chapter on the poster-sized mesh"
  "$BUILD_DIR/fem_bench" --json results/bench.json "$@"
  if [ -f scripts/plot_results.py ]; then
    log "plotting"
    "$VENV/bin/python" scripts/plot_results.py results/bench.json --out results
  fi
}

threads() {
  build
  mkdir -p results
  local counts
  counts=$(seq -s, 1 "$(nproc)")
  log "chapter 09 at $counts threads (chapter 08 beside it, one thread) on the poster-sized mesh"
  "$BUILD_DIR/fem_bench" --chapters 08,09 --threads "$counts" --no-solvers \
    --json results/threads.json "$@"
  "$VENV/bin/python" scripts/plot_results.py --threads results/threads.json --out results
}

scaling() {
  build
  log "scaling over the beam series (a time budget per run; --help for the options)"
  "$VENV/bin/python" scripts/scaling.py --bench "$BUILD_DIR/fem_bench" --out results/scaling.json "$@"
  "$VENV/bin/python" scripts/plot_results.py --scaling results/scaling.json --out results
}

docs() {
  build
  [ -f results/bench.json ] || { echo "no results/bench.json: run ./tutorial.sh bench first" >&2; exit 1; }
  log "lesson tables (fem_lessons)"
  "$BUILD_DIR/fem_lessons" noalias --readme chapters/02_noalias/README.md >/dev/null
  "$BUILD_DIR/fem_lessons" dfdx-fill --readme chapters/03_indexed_access/README.md >/dev/null
  "$BUILD_DIR/fem_lessons" spmv --readme chapters/07_block_sparse/README.md >/dev/null
  "$BUILD_DIR/fem_lessons" rotations --readme chapters/08_element_kernels/README.md >/dev/null
  "$BUILD_DIR/fem_lessons" threads-element --readme chapters/09_threads/README.md >/dev/null
  log "results tables and plots"
  "$VENV/bin/python" scripts/update_docs.py --images docs/images
  log "chapter diffs (docs/diffs/)"
  "$VENV/bin/python" scripts/chapter_diffs.py
  if [ -x "$BUILD_DIR/fem_viewer" ] && command -v xvfb-run >/dev/null; then
    log "viewer screenshot (headless, Xvfb): docs/images/viewer.png"
    xvfb-run -a -s "-screen 0 1280x800x24" "$BUILD_DIR/fem_viewer" --frames 90 \
      --replay-drag auto --screenshot docs/images/viewer.png >/dev/null
  fi
}

sim() {
  build
  log "simulating the cantilever on the poster-sized mesh (VTK frames in out/sim/)"
  "$BUILD_DIR/fem_sim" --out out/sim --every 4 "$@"
  log "rendering the frames to docs/images/cantilever.gif"
  local pvd
  pvd=$(ls -t out/sim/*.pvd | head -n 1)
  "$VENV/bin/python" scripts/render_gif.py "$pvd" --out docs/images/cantilever.gif
}

viewer() {
  build
  [ -x "$BUILD_DIR/fem_viewer" ] || { echo "fem_viewer was not built (see the CMake warning)" >&2; exit 1; }
  log "opening the viewer (space: pause, s: step, r: reset; drag the body with the mouse)"
  "$BUILD_DIR/fem_viewer" "$@"
}

viewer_bench() {
  build
  [ -x "$BUILD_DIR/fem_viewer" ] || { echo "fem_viewer was not built (see the CMake warning)" >&2; exit 1; }
  log "the viewer's frame rate per chapter, headless (Xvfb, Mesa's software OpenGL)"
  "$VENV/bin/python" scripts/viewer_fps.py --viewer "$BUILD_DIR/fem_viewer" --out results/viewer.json "$@"
}

meshes() {
  setup_venv
  "$VENV/bin/python" meshes/generate.py "$@"
}

main() {
  cmd="${1:-help}"
  [ $# -gt 0 ] && shift
  case "$cmd" in
    setup) setup ;;
    build) build ;;
    test) run_tests "$@" ;;
    bench) bench "$@" ;;
    scaling) scaling "$@" ;;
    threads) threads "$@" ;;
    docs) docs ;;
    sim) sim "$@" ;;
    viewer) viewer "$@" ;;
    viewer-bench) viewer_bench "$@" ;;
    meshes) meshes "$@" ;;
    help | --help | -h) usage ;;
    *)
      echo "tutorial.sh: unknown command '$cmd'" >&2
      usage >&2
      exit 2
      ;;
  esac
}

# Parsed whole before it runs: editing this file while it runs cannot derail it.
main "$@"
exit $?
