#!/usr/bin/env bash
# One entry point for the tutorial: set-up, build, tests, benchmark, simulation.
# Every subcommand sets up what is missing first (idempotent), so a fresh clone of the
# repository on Debian or Ubuntu (apt), Fedora (dnf) or macOS (Homebrew) needs nothing but this
# script (and, without root, the one install line it prints).
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
cd "$ROOT"
PRESET="${PRESET:-release}"           # release | debug | asan | clang | catch2-3
BUILD_DIR="$ROOT/build/$PRESET"
VENV="$ROOT/.venv"
SKIPPED_PACKAGES="$ROOT/build/.packages-skipped"  # optional packages this system's sources lack

# The system packages, per package manager: apt (Debian, Ubuntu), dnf (Fedora), Homebrew
# (macOS). Each has a list the build cannot do without and optional groups, each named with
# what its absence costs: a platform that lacks one (likwid on arm64 and macOS, the viewer's
# libraries) installs the rest and says what is skipped.
APT_PACKAGES=(
  build-essential cmake ninja-build git python3 python3-venv pkg-config
  # the compiler cache: a build folder, a copy of the repository (the coursework tests) or
  # another preset compiles only what it compiles differently (CMakeLists.txt)
  ccache
  libeigen3-dev catch2
  # CHOLMOD, for the supernodal Cholesky row of fem_bench's solve table (Eigen's CholmodSupport)
  libsuitesparse-dev
  # JSON written and read in C++ (header-only); OpenMP's runtime
  nlohmann-json3-dev libgomp1
)
# likwid-bench, the independent check of the roofline's bandwidth and peak (fem_lessons
# roofline): Debian and Ubuntu package it for x86-64 only.
APT_LIKWID=(likwid)
APT_PYTHON=(python3 python3-venv)
# gmsh's runtime libraries (the PyPI wheel links against them)
APT_GMSH=(libglu1-mesa libgl1 libxrender1 libxcursor1 libxft2 libxinerama1 libfontconfig1)
# the viewer: GLFW, OpenGL, Dear ImGui (with its GLFW and OpenGL 3 backends), stb for the
# screenshots; Xvfb and Mesa's software renderer run it headless in the tests
APT_VIEWER=(libglfw3-dev libgl-dev libimgui-dev libstb-dev xvfb xauth libgl1-mesa-dri)
# Fedora (catch-devel is Catch2 3; json-devel is nlohmann-json).
DNF_PACKAGES=(gcc-c++ cmake ninja-build git python3 pkgconf-pkg-config ccache eigen3-devel
              catch-devel suitesparse-devel json-devel libgomp)
DNF_LIKWID=(likwid)
DNF_PYTHON=(python3)
DNF_GMSH=(mesa-libGLU mesa-libGL libXrender libXcursor libXft libXinerama fontconfig)
DNF_VIEWER=(glfw-devel mesa-libGL-devel xorg-x11-server-Xvfb xorg-x11-xauth mesa-dri-drivers)
# macOS: Apple's Clang with Homebrew's OpenMP runtime; Homebrew has no likwid (it reads Intel
# and AMD counters under Linux), and gmsh's macOS wheel carries its own libraries.
BREW_PACKAGES=(cmake ninja ccache python pkg-config eigen catch2 suite-sparse nlohmann-json libomp)
BREW_VIEWER=(glfw)
BREW_PYTHON=(python)
# What is lost without each optional group.
COST_LIKWID="no check of the roofline's roofs against likwid-bench (fem_lessons roofline runs without it and says so)"
COST_GMSH="no gmsh for generating meshes (./tutorial.sh meshes): the committed meshes serve"
COST_VIEWER="no interactive viewer (fem_viewer) nor its headless tests"
# What the other presets add: the clang preset builds with Clang and its OpenMP runtime (and
# brings clang-format, which keeps the sources in .clang-format's style: CI checks it); the
# catch2-3 preset unpacks Catch2 3 from bookworm-backports into build/ (tools/catch2_3.sh,
# which installs nothing).
case "$PRESET" in
  clang)
    APT_PACKAGES+=(clang clang-format libomp-dev)
    DNF_PACKAGES+=(clang clang-tools-extra libomp-devel)
    BREW_PACKAGES+=(clang-format)
    ;;
esac

usage() {
  cat <<USAGE
usage: ./tutorial.sh <command> [arguments passed to the program]

commands:
  setup      install what is missing (system packages with apt, dnf or brew; .venv with
             requirements.txt), configure, build
  build      set up if needed and build (preset: \$PRESET, default release); one build at a time
             in a build folder: a command that builds while another does waits for it, saying so
  test       build and run every test through ctest but the new-chapter test, which builds a
             copy of the repository (ctest arguments may follow, e.g. -L ch01 or -L new-chapter)
  bench      build (quietly) and benchmark every chapter on the poster-sized mesh: prints the
             per-phase table; a run is a folder, --out DIR (default: a new results/run-DATE-TIME,
             with results/latest pointing to it) gets bench.json and the plots made from it; a
             folder holding a run is refused unless --replace; other arguments go to fem_bench
             (--chapters 06,07, --mesh, --scene, --steps; fem_bench --help)
  diff       a variant's change against its original, the copy's renames undone (the hand-in):
             ./tutorial.sh diff 06_my_fused_updates
  handin-check
             a teacher's check of a hand-in: ./tutorial.sh handin-check handin/06_fused (the
             variant's sources against the run's record, its diff, its tests, the plots
             regenerated from the JSON; docs/coursework.md)
  plots      remake the plots of a run folder from its bench.json: ./tutorial.sh plots DIR
  compare    a run beside another (default: the committed docs/data/bench.json): each chapter's
             speedup over chapter 01 per phase in both, the differences beyond the runs' spread
             marked, what differs in the two records (instruction set, cores, compiler, load),
             and DIR/compare.png: ./tutorial.sh compare RUN [REFERENCE]
  variant    copy a chapter under a new name to change it and measure it against the
             original: ./tutorial.sh variant 06 my_fused_updates (chapters/README.md)
  scaling    build and run the chapters over the beam series up to about 100,000 nodes (large
             meshes generated on demand), with a time budget per run: results/scaling.json and
             results/scaling.png
  regimes    build and run every chapter on both poster-sized bodies (the thin plate, the perforated
             bar) over a sweep of Young's modulus, with the solve table at each point (a few
             minutes on 2 cores): results/regimes.json and results/regimes.png; arguments go to
             fem-tools runs regimes (--help)
  threads    build and measure chapter 09 (and 08 beside it) at 1, 2, ... up to every hardware
             thread on the poster-sized mesh: results/threads.json and results/threads.png
             (step and solve time against threads, with the ideal line)
  book       record the book in one sitting on this machine (about 45 minutes on 2 cores; it
             refuses a busy machine unless --busy): the bench, the thread sweep, the scaling
             series, the regime sweep, the viewer's frame rate, every lesson and the roofline,
             then the docs regenerated from them and docs/data/book.json, which ties the data
             to the code it measured (ctest -L docs checks it)
  docs       commit the run in results/latest (or the folder given) (and results/*.json) as docs/data/*.json and regenerate the generated parts
             of the docs from it (tables in docs/results.md, the README and the chapter
             READMEs, plots in docs/images/; ctest -L docs checks they match), the lesson
             tables (fem_lessons), the figures of chapters 10-12 (fem-tools plots figures), the
             chapter diffs (docs/diffs/), the cantilever's animation (docs/images/cantilever.gif) and the viewer's screenshot
             (docs/images/viewer.png, headless); run bench first (scaling, viewer-bench, regimes
             too, for their tables: without their results the committed tables stay)
  lessons    measure the lesson tables (fem_lessons, fem-tools runs pyamg; a few minutes),
             record them in docs/data/lessons/*.json and write them into the chapter READMEs
             (ctest -L docs checks that the READMEs hold the recorded tables), and the data of
             the figures (fem_figure_data: docs/data/figures/*.json); part of docs
  roofline   build and measure this machine's roofs (read and write bandwidth of each cache level
             and of memory, peak multiply-add rate in double and float, on 1 and every thread,
             each beside likwid-bench's) and place every chapter's phases under them, over
             fem_bench's 10 warm-up and 100 measured steps (fem_lessons roofline; a few minutes):
             results/roofline.json and results/roofline.png (docs/roofline.md explains them);
             --out DIR for another run folder, other arguments go to fem_lessons roofline
             (--chapters 12,12_mine, --meshes, --steps; fem_lessons roofline --help)
  sim        build and run the cantilever on the poster-sized mesh (VTK frames in out/sim/, open
             out/sim/cantilever.pvd in ParaView) and render them to out/sim/cantilever.gif
             (--out DIR for another folder; docs renders docs/images/cantilever.gif)
  viewer-bench
             build and measure the viewer's frame rate per chapter on the poster-sized mesh,
             headless (Xvfb): results/viewer.json, shown in the README by docs
  viewer     build and open the interactive viewer (fem_viewer --help for its options): drag the
             body with the mouse, switch chapters live; needs a display
  meshes     regenerate the committed meshes with gmsh (meshes/generate.py)
  tools      the Python tooling of this tree: ./tutorial.sh tools GROUP COMMAND (results, docs,
             plots, runs, course, check; ./tutorial.sh tools --help lists them), the same as
             .venv/bin/fem-tools, which the set-up installs (tools/femtools)
  help       this text (also --help, -h)

environment:
  PRESET=release|debug|asan|clang|catch2-3
                 which CMake preset to build and test with (default release; clang: compiled by
                 Clang; catch2-3: tested with Catch2 3, fetched into build/deps/ by
                 tools/catch2_3.sh; CMakePresets.json)
  FEM_SKIP_PACKAGES=1
                 do not check or install system packages (for systems without apt-get, dnf
                 or brew, once their packages are installed by hand: docs/reference.md,
                 "Other systems")
USAGE
}

log() { printf '\033[1m==> %s\033[0m\n' "$*"; }

# The system's package manager: apt (Debian, Ubuntu), dnf (Fedora), brew (macOS), or none.
package_manager() {
  if command -v apt-get >/dev/null && command -v dpkg-query >/dev/null; then echo apt
  elif command -v dnf >/dev/null && command -v rpm >/dev/null; then echo dnf
  elif command -v brew >/dev/null; then echo brew
  else echo none
  fi
}

# packages_of PM GROUP: the packages of one group (required, python, likwid, gmsh, viewer), from
# the arrays above (APT_PACKAGES, APT_LIKWID, ...; bash 3.2, macOS's, has no namerefs).
packages_of() {
  local name
  name=$(printf '%s_%s' "$1" "$2" | tr '[:lower:]' '[:upper:]')
  name=${name/%_REQUIRED/_PACKAGES}
  eval "echo \${$name[*]:-}"
}

cost_of() {
  case "$1" in
    likwid) echo "$COST_LIKWID" ;;
    gmsh) echo "$COST_GMSH" ;;
    viewer) echo "$COST_VIEWER" ;;
  esac
}

# The command that installs every package of a system, optional groups included.
install_line() {
  local all
  all="$(packages_of "$1" required) $(packages_of "$1" likwid) $(packages_of "$1" gmsh) $(packages_of "$1" viewer)"
  all=$(echo $all)  # one space between names
  case "$1" in
    apt) echo "sudo apt-get install -y $all" ;;
    dnf) echo "sudo dnf install -y $all" ;;
    brew) echo "brew install $all" ;;
  esac
}

installed() {  # installed PM PACKAGE
  case "$1" in
    apt) dpkg-query -W -f='${Status}' "$2" 2>/dev/null | grep -q "install ok installed" ;;
    dnf) rpm -q --whatprovides "$2" >/dev/null 2>&1 ;;
    brew) brew list --versions "$2" >/dev/null 2>&1 ;;
  esac
}

# Whether apt's lists (as they are) have a candidate for the package on this architecture.
apt_available() {
  local candidate
  candidate=$(apt-cache policy "$1" 2>/dev/null | awk '/Candidate:/ { print $2 }')
  [ -n "$candidate" ] && [ "$candidate" != "(none)" ]
}

# Without a package manager it knows, the script cannot install anything: it says so, with
# the complete line for each system it knows, and stops.
refuse_without_package_manager() {
  cat >&2 <<REFUSE
tutorial.sh installs its system packages with apt-get (Debian, Ubuntu), dnf (Fedora) or brew
(macOS), and this system has none of them. Install them by hand (docs/reference.md, "Other
systems"); on those systems the lines are:
  Debian, Ubuntu:   $(install_line apt)
  Fedora:           $(install_line dnf)
  macOS (Homebrew): $(install_line brew)
(likwid has no package for arm64 nor macOS, and the viewer's libraries are optional: without
them the rest builds, and what is missing is named.) Then run the same command again with
FEM_SKIP_PACKAGES=1, e.g.
  FEM_SKIP_PACKAGES=1 ./tutorial.sh test
(CMake then reports anything still missing.)
REFUSE
  exit 1
}

# Installs what is missing of the required packages and of each optional group (default), or of
# Python's alone (argument python). A required package that cannot be installed stops the script
# with the line to run; an optional group that cannot is skipped, named with what it costs.
install_system_packages() {
  [ "${FEM_SKIP_PACKAGES:-0}" = 1 ] && return 0
  local pm groups=(required likwid gmsh viewer)
  pm=$(package_manager)
  [ "$pm" = none ] && refuse_without_package_manager
  [ "${1:-}" = python ] && groups=(python)
  local group p missing=() skipped=""
  # Optional packages found missing from this system's sources once are not looked up again.
  [ -f "$SKIPPED_PACKAGES" ] && skipped=$(cat "$SKIPPED_PACKAGES")
  for group in "${groups[@]}"; do
    for p in $(packages_of "$pm" "$group"); do
      [[ " $skipped " == *" $group:$p "* ]] && continue
      installed "$pm" "$p" || missing+=("$group:$p")
    done
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  case "$pm" in
    apt) install_with_apt "${missing[@]}" ;;
    dnf) install_with_dnf "${missing[@]}" ;;
    brew) install_with_brew "${missing[@]}" ;;
  esac
}

# The names of the GROUP:NAME arguments of one group ("required" or "optional").
names_of() {
  local kind=$1 entry
  shift
  for entry in "$@"; do
    case "$kind:${entry%%:*}" in
      required:required | required:python | optional:likwid | optional:gmsh | optional:viewer)
        printf '%s ' "${entry#*:}" ;;
    esac
  done
}

say_skipped() {  # say_skipped GROUP WHY [PACKAGES]: PACKAGES default to the whole group
  local names=${3:-$(packages_of "$PM_NOW" "$1")}
  echo "tutorial.sh: skipped ${names% } ($2): without it, $(cost_of "$1")" >&2
}

# Without root, the script prints the line to run: it stops when a required package is missing,
# and goes on when only optional ones are.
ask_root() {  # ask_root COMMAND REQUIRED_MISSING
  echo "Missing system packages. Please run:" >&2
  echo "  $1" >&2
  if [ -n "${2// /}" ]; then
    echo "then run ./tutorial.sh again." >&2
    exit 1
  fi
  echo "(optional packages: the rest is built without them)" >&2
}

install_with_apt() {
  local entry p install="" required unavailable="" skipped="" group
  PM_NOW=apt
  [ "$(id -u)" -eq 0 ] && { DEBIAN_FRONTEND=noninteractive apt-get update -qq || true; }
  # One name apt does not know would abort the whole install: each is looked up first.
  for entry in "$@"; do
    p=${entry#*:}
    if apt_available "$p"; then
      install+="$p "
    elif [[ "$entry" == required:* || "$entry" == python:* ]]; then
      unavailable+="$p "
    else
      skipped+="$entry "
    fi
  done
  for group in likwid gmsh viewer; do
    p=$(printf '%s\n' $skipped | sed -n "s/^$group://p" | tr '\n' ' ')
    [ -z "$p" ] || say_skipped "$group" "apt has none for $(uname -m) in this system's sources" "$p"
  done
  if [ -n "$skipped" ]; then
    mkdir -p "$(dirname "$SKIPPED_PACKAGES")"
    echo "$skipped" >>"$SKIPPED_PACKAGES"
  fi
  if [ -n "$unavailable" ]; then
    echo "tutorial.sh: apt has no package $unavailable(needed to build; on Ubuntu enable universe: sudo add-apt-repository universe)." >&2
    echo "The complete line: $(install_line apt)" >&2
    exit 1
  fi
  [ -n "$install" ] || return 0
  required=$(names_of required "$@")
  if [ "$(id -u)" -ne 0 ]; then
    ask_root "sudo apt-get install -y ${install% }" "$required"
    return 0
  fi
  log "installing Debian packages: $install"
  # shellcheck disable=SC2086
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends $install
}

install_with_dnf() {
  local required optional group
  PM_NOW=dnf
  required=$(names_of required "$@")
  optional=$(names_of optional "$@")
  if [ "$(id -u)" -ne 0 ]; then
    ask_root "sudo dnf install -y $(echo $required$optional)" "$required"
    return 0
  fi
  if [ -n "${required// /}" ]; then
    log "installing Fedora packages: $required"
    # shellcheck disable=SC2086
    dnf install -y $required || {
      echo "tutorial.sh: dnf could not install them; the complete line: $(install_line dnf)" >&2
      exit 1
    }
  fi
  # Each optional group alone: one that dnf lacks is skipped, the others install.
  for group in likwid gmsh viewer; do
    printf '%s\n' "$@" | grep -q "^$group:" || continue
    # shellcheck disable=SC2046
    dnf install -y $(packages_of dnf "$group") || say_skipped "$group" "dnf could not install it"
  done
}

install_with_brew() {
  local required group
  PM_NOW=brew
  required=$(names_of required "$@")
  if [ -n "${required// /}" ]; then
    log "installing Homebrew packages: $required"
    # shellcheck disable=SC2086
    brew install $required || {
      echo "tutorial.sh: brew could not install them; the complete line: $(install_line brew)" >&2
      exit 1
    }
  fi
  for group in viewer; do
    printf '%s\n' "$@" | grep -q "^$group:" || continue
    # shellcheck disable=SC2046
    brew install $(packages_of brew "$group") || say_skipped "$group" "brew could not install it"
  done
  # Homebrew has no likwid (it reads Intel's and AMD's counters under Linux): said with the rest.
  echo "tutorial.sh: Homebrew has no likwid: without it, $COST_LIKWID" >&2
}

# Portable stand-ins for GNU coreutils (macOS has neither nproc nor sha256sum). A system with
# none of the fallbacks stops, naming the tool and the line that installs it.
cores() {
  nproc 2>/dev/null || getconf _NPROCESSORS_ONLN 2>/dev/null || sysctl -n hw.ncpu 2>/dev/null || {
    echo "tutorial.sh: cannot count the cores: no nproc, getconf nor sysctl (install coreutils: sudo apt-get install coreutils, sudo dnf install coreutils, brew install coreutils)" >&2
    exit 1
  }
}

sha256() {  # the SHA-256 of standard input, in hex
  if command -v sha256sum >/dev/null; then
    sha256sum | cut -d' ' -f1
  elif command -v shasum >/dev/null; then
    shasum -a 256 | cut -d' ' -f1
  elif command -v python3 >/dev/null; then
    python3 -c 'import hashlib, sys; print(hashlib.sha256(sys.stdin.buffer.read()).hexdigest())'
  else
    echo "tutorial.sh: no sha256sum, shasum nor python3 to hash requirements.txt (install coreutils: sudo apt-get install coreutils, sudo dnf install coreutils, brew install coreutils)" >&2
    exit 1
  fi
}

# Whether .venv's fem-tools imports: an editable install points at the tree that made it, which
# may have been removed since (a second worktree sharing the .venv).
tools_installed() {
  (cd / && PYTHONPATH="" "$VENV/bin/python" -c "import femtools.cli" 2>/dev/null)
}

setup_venv() {
  local stamp="$VENV/.requirements.sha256"
  local want
  want=$(cat requirements.txt tools/pyproject.toml | sha256)
  if [ -x "$VENV/bin/python" ] && [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$want" ] \
    && tools_installed; then
    return 0
  fi
  log "creating .venv and installing requirements.txt (gmsh, matplotlib) and tools/ (fem-tools)"
  [ -x "$VENV/bin/python" ] || python3 -m venv "$VENV"
  local pip=("$VENV/bin/python" -m pip install --quiet --disable-pip-version-check) rest gmsh_pin
  # gmsh apart: PyPI has no wheel of it for every system (none for Linux on arm64), and the
  # course goes on without it.
  rest=$(mktemp)
  grep -v '^gmsh==' requirements.txt >"$rest"
  "${pip[@]}" -r "$rest"
  rm -f "$rest"
  gmsh_pin=$(sed -n 's/^\(gmsh==[^ ]*\).*/\1/p' requirements.txt)
  if ! "${pip[@]}" --only-binary gmsh "$gmsh_pin" 2>/dev/null; then
    echo "tutorial.sh: pip could not install $gmsh_pin on $(uname -s) $(uname -m) (PyPI has no wheel of it for Linux on arm64): the set-up goes on without gmsh. The committed meshes (meshes/*.msh) serve every chapter, test and benchmark; what cannot be made here is a new mesh (./tutorial.sh meshes, the large beams of ./tutorial.sh scaling)." >&2
  fi
  "$VENV/bin/python" -m pip install --quiet --disable-pip-version-check --no-deps -e tools/
  echo "$want" >"$stamp"
}

# The Python tooling, `fem-tools GROUP COMMAND` (tools/femtools; `./tutorial.sh tools --help`):
# this tree's own package first on the path, whatever .venv has installed, so that a copy of the
# repository (the coursework tests make them) or a second worktree runs its own tools.
fem_tools() {
  PYTHONPATH="$ROOT/tools${PYTHONPATH:+:$PYTHONPATH}" "$VENV/bin/python" -m femtools "$@"
}

configure() {
  if [ "$PRESET" = catch2-3 ]; then
    tools/catch2_3.sh >/dev/null
  fi
  # Apple's Clang has no OpenMP runtime of its own: CMake finds Homebrew's (libomp) there.
  if [ -z "${OpenMP_ROOT:-}" ] && command -v brew >/dev/null; then
    OpenMP_ROOT=$(brew --prefix libomp 2>/dev/null || true)
    export OpenMP_ROOT
  fi
  if [ ! -f "$BUILD_DIR/CMakeCache.txt" ]; then
    log "configuring (preset $PRESET)"
    cmake --preset "$PRESET"
  fi
}

# What the Python scripts need (plots, variants, meshes): python3 and its venv, and .venv.
setup_python() {
  install_system_packages python3 python3-venv
  setup_venv
}

# The packages first: on a system the script cannot install on, its first words say what to
# install, whatever else it lacks. Then the lock, then the rest of the set-up under it.
setup() {
  install_system_packages
  take_build_lock
  setup_venv
  configure
}

# One build at a time in a build folder: two commands started together (two benches on a
# stale build) once ran two ninjas in one folder, and one failed with a linker error that read
# like a code error. The lock covers the set-up after the packages, the build and its log; it is
# released when the build ends, before the programs run, or with the process. The second command
# waits for it, saying so. flock on a file in the build folder (fd 9) where flock exists (Linux);
# elsewhere (macOS) a directory, which mkdir makes or fails to make in one step, holding the
# owner's process id: a lock whose owner no longer runs is taken over.
take_build_lock() {
  mkdir -p "$BUILD_DIR"
  if command -v flock >/dev/null; then
    exec 9>"$BUILD_DIR/.build.lock"
    flock -n 9 && return 0
    say_waiting
    flock 9
  else
    LOCK_DIR="$BUILD_DIR/.build.lock.d"
    local waited=0 owner
    until mkdir "$LOCK_DIR" 2>/dev/null; do
      owner=$(cat "$LOCK_DIR/pid" 2>/dev/null || true)
      if [ -n "$owner" ] && ! kill -0 "$owner" 2>/dev/null; then
        rm -rf "$LOCK_DIR"
        continue
      fi
      [ "$waited" -eq 1 ] || say_waiting
      waited=1
      sleep 1
    done
    echo $$ >"$LOCK_DIR/pid"
    trap release_build_lock EXIT
    [ "$waited" -eq 1 ] || return 0
  fi
  echo "the other build ended: building" >&2
}

say_waiting() {
  echo "another command is building in ${BUILD_DIR#"$ROOT"/}: waiting for its build to end" >&2
}

release_build_lock() {
  exec 9>&-
  if [ -n "${LOCK_DIR:-}" ]; then
    rm -rf "$LOCK_DIR"
    LOCK_DIR=""
  fi
}

build() {
  setup
  log "building (preset $PRESET)"
  cmake --build --preset "$PRESET"
  release_build_lock
}

# Ninja's progress from the build's output, "[n/N] what": on a terminal one line rewritten in
# place, otherwise a line at every tenth of the build, so that a first build (minutes) is never
# silent. Every line goes on to the log.
build_progress() {
  local build_log="$1" tty=0 line count total last=-1 said=$SECONDS
  [ -t 1 ] && tty=1
  while IFS= read -r line; do
    printf '%s\n' "$line" >>"$build_log"
    [[ "$line" =~ ^\[([0-9]+)/([0-9]+)\] ]] || continue
    count=${BASH_REMATCH[1]} total=${BASH_REMATCH[2]}
    if [ "$tty" -eq 1 ]; then
      printf '\r\033[K  [%s/%s] %.100s' "$count" "$total" "${line#*] }"
    elif [ $((count * 10 / total)) -ne "$last" ] || [ "$count" -eq "$total" ] ||
      [ $((SECONDS - said)) -ge 30 ]; then
      last=$((count * 10 / total)) said=$SECONDS
      printf '  [%s/%s] %s\n' "$count" "$total" "${line#*] }"
    fi
  done
  [ "$tty" -eq 1 ] && printf '\r\033[K'
  return 0
}

# The build with its log kept out of the way of the results that follow: ninja's progress, the
# log's tail on failure, and the warnings (if any) named.
quiet_build() {
  setup
  local build_log="$BUILD_DIR/build.log"
  log "building (preset $PRESET; log in ${build_log#"$ROOT"/})"
  : >"$build_log"
  if ! cmake --build --preset "$PRESET" 2>&1 | build_progress "$build_log"; then
    tail -n 40 "$build_log" >&2
    echo "the build failed: the whole log is $build_log" >&2
    exit 1
  fi
  local warnings
  warnings=$(grep -c "warning:" "$build_log" || true)
  [ "$warnings" -eq 0 ] || echo "the build printed $warnings warnings: see $build_log" >&2
  release_build_lock
}

run_tests() {
  build
  log "running the tests"
  # The new-chapter test builds a copy of the repository with a chapter added (minutes): left
  # out unless the arguments name it or exclude labels of their own (.ci/run runs it apart).
  local select=(-LE new-chapter)
  [[ "$*" == *new-chapter* || " $* " == *" -LE "* ]] && select=()
  ctest --preset "$PRESET" -j "$(cores)" ${select[@]+"${select[@]}"} "$@" 2>&1 | with_heartbeat
  return "${PIPESTATUS[0]}"
}

# Passes its input on, and when it has been silent for 30 s says so with the time since the
# start: ctest prints a test only when it ends, and the coursework tests (labels variants and
# exercises) build copies of the repository for minutes.
with_heartbeat() {
  local line start=$SECONDS done=0 status
  while :; do
    # (the status taken inside a condition: under set -e a timed-out read would end the script)
    status=0
    IFS= read -r -t 30 line || status=$?
    if [ "$status" -eq 0 ]; then
      printf '%s\n' "$line"
      [[ "$line" =~ Test\ +#[0-9]+: ]] && done=$((done + 1))
    elif [ "$status" -gt 128 ]; then
      printf '  ... %d s, %d tests finished; still running (the coursework tests build copies of the repository)\n' \
        $((SECONDS - start)) "$done"
    else
      [ -n "$line" ] && printf '%s\n' "$line"
      break
    fi
  done
}

# A run is a folder: fem_bench writes DIR/bench.json and the plots are made from that file,
# so plots and numbers always belong together.
bench() {
  local out="" json="" no_json=0 args=("$@") i
  for ((i = 0; i < ${#args[@]}; i++)); do
    case "${args[i]}" in
      --out) out="${args[i + 1]:-}"; [ -n "$out" ] || { echo "tutorial.sh bench: --out needs a folder" >&2; exit 2; } ;;
      --json) json="${args[i + 1]:-}" ;;
      --no-json) no_json=1 ;;
    esac
  done
  # The run's folder before the build and the run (fem_bench checks its other arguments before
  # its work, too): a place that cannot be written fails now, not minutes later. Without --out,
  # fem_bench makes a new folder results/run-DATE-TIME and points results/latest at it: a run
  # never replaces an earlier one unless asked (--replace).
  if ! mkdir -p "${out:-results}" 2>/dev/null || [ ! -w "${out:-results}" ]; then
    echo "tutorial.sh bench: cannot write the run's folder '${out:-results}'" >&2
    exit 2
  fi
  quiet_build
  log "benchmarking: fem_bench $* (the run's folder: ${out:-a new one under results/})"
  "$BUILD_DIR/fem_bench" "$@"
  if [ "$no_json" -eq 1 ]; then
    return 0  # no JSON, no plots (results/latest still names the last run that wrote one)
  elif [ -n "$json" ]; then
    plots "$json" "${out:-$(dirname "$json")}"
  else
    out="${out:-results/$(readlink results/latest)}"
    plots "$out/bench.json" "$out"
  fi
}

# Plots of one run from its JSON: ./tutorial.sh plots DIR (or a bench.json and a folder).
plots() {
  local json="${1:-results}" out="${2:-}"
  [ -d "$json" ] && { out="${out:-$json}"; json="$json/bench.json"; }
  out="${out:-$(dirname "$json")}"
  [ -f "$json" ] || { echo "tutorial.sh plots: no $json (usage: ./tutorial.sh plots DIR)" >&2; exit 2; }
  setup_python
  log "plotting $json into $out/"
  fem_tools plots bench "$json" --out "$out"
}

compare() {
  [ $# -ge 1 ] && [ $# -le 2 ] || { echo "usage: ./tutorial.sh compare RUN [REFERENCE] (run folders or bench.json files)" >&2; exit 2; }
  setup_python
  fem_tools course compare "$@"
}

variant() {
  [ $# -eq 2 ] || { echo "usage: ./tutorial.sh variant NN NAME (e.g. 06 my_fused_updates)" >&2; exit 2; }
  setup_python
  fem_tools course variant -- "$@"  # after --: a name such as -x is checked as a name
}

# A teacher's check of a hand-in (fem-tools course handin --help): the variant's sources against
# the run's record, its diff, its tests, the plots regenerated from the JSON.
handin_check() {
  [ $# -ge 1 ] || { echo "usage: ./tutorial.sh handin-check FOLDER [--variant NN_NAME] (a run's folder handed in)" >&2; exit 2; }
  build
  fem_tools course handin --build "$BUILD_DIR" "$@"
}

diff_variant() {
  [ $# -eq 1 ] || { echo "usage: ./tutorial.sh diff VARIANT (its name, e.g. my_fused_updates, or its folder 06_my_fused_updates)" >&2; exit 2; }
  fem_tools docs diffs --variant "$1"
}

threads() {
  quiet_build
  mkdir -p results
  local counts
  counts=$(seq -s, 1 "$(cores)")
  log "chapter 09 at $counts threads (chapter 08 beside it, one thread) on the poster-sized mesh"
  "$BUILD_DIR/fem_bench" --chapters 08,09 --threads "$counts" --no-solvers \
    --json results/threads.json --replace "$@"
  fem_tools plots bench --threads results/threads.json --out results
}

scaling() {
  quiet_build
  log "scaling over the beam series (a time budget per run; --help for the options)"
  fem_tools runs scaling --bench "$BUILD_DIR/fem_bench" --out results/scaling.json "$@"
  fem_tools plots bench --scaling results/scaling.json --out results
}

regimes() {
  build
  log "the regime sweep: every chapter, both poster-sized bodies, E over decades (fem-tools runs regimes --help)"
  fem_tools runs regimes --bench "$BUILD_DIR/fem_bench" --out results/regimes.json "$@"
}

lessons() {
  quiet_build
  log "lesson tables (fem_lessons, fem-tools runs pyamg: a few minutes), recorded in docs/data/lessons/"
  # Chapter 11's table sets gmsh's own orders beside the chapter's: the meshes they number first.
  fem_tools runs renumber-meshes >/dev/null
  # Every lesson with the arguments it carries (Lesson::record_args; the 82k-node beam too when
  # `./tutorial.sh meshes --large` made it).
  "$BUILD_DIR/fem_lessons" record-all --out docs/data/lessons >/dev/null
  fem_tools runs pyamg --tool "$BUILD_DIR/fem_lessons" \
    --json docs/data/lessons/pyamg.json >/dev/null
  fem_tools plots roofline docs/data/lessons/roofline.json --out docs/images/roofline.png
  fem_tools docs lessons
  # The code's own data behind the figures of chapters 10 and 11 (fem-tools plots figures draws them).
  mkdir -p docs/data/figures
  "$BUILD_DIR/fem_figure_data" hierarchy --mesh meshes/plate_poster.msh \
    --json docs/data/figures/hierarchy.json
  "$BUILD_DIR/fem_figure_data" node-orders --mesh meshes/beam_10k.msh \
    --json docs/data/figures/node-orders.json
}

# This machine's roofs and every chapter under them, into a run folder (results/ by default).
roofline() {
  quiet_build
  local out=results
  if [ "${1:-}" = "--out" ]; then out="$2"; shift 2; fi
  mkdir -p "$out"
  log "the roofline: this machine's roofs and every chapter's phases under them, into $out/"
  "$BUILD_DIR/fem_lessons" roofline --steps 100 --json "$out/roofline.json" "$@"
  fem_tools plots roofline "$out/roofline.json" --out "$out/roofline.png"
}

docs() {
  quiet_build
  local run=${1:-results/latest}
  [ -f "$run/bench.json" ] || { echo "no $run/bench.json: run ./tutorial.sh bench first" >&2; exit 1; }
  lessons
  log "results: the run's JSON committed under docs/data/, tables and plots from it"
  mkdir -p docs/data
  cp "$run/bench.json" docs/data/bench.json
  for json in scaling viewer regimes threads; do
    if [ -f "results/$json.json" ]; then cp "results/$json.json" "docs/data/$json.json"; fi
  done
  fem_tools plots bench docs/data/bench.json --out docs/images
  if [ -f docs/data/scaling.json ]; then
    fem_tools plots bench --scaling docs/data/scaling.json --out docs/images
  fi
  if [ -f docs/data/threads.json ]; then
    fem_tools plots bench --threads docs/data/threads.json --out docs/images
  fi
  if [ -f results/regimes.png ]; then cp results/regimes.png docs/images/regimes.png; fi
  log "figures of chapters 10-12 (fem-tools plots figures, from docs/data/figures/ and the code)"
  fem_tools plots figures --out docs/images
  fem_tools docs update
  log "chapter diffs (docs/diffs/) and the phase-owners table (fem_lessons phase-owners)"
  fem_tools docs diffs
  "$BUILD_DIR/fem_lessons" phase-owners --write chapters/README.md
  log "the cantilever's animation (docs/images/cantilever.gif, from ./tutorial.sh sim's run)"
  sim --out out/docs_sim >/dev/null
  cp out/docs_sim/cantilever.gif docs/images/cantilever.gif
  if [ -x "$BUILD_DIR/fem_viewer" ] && command -v xvfb-run >/dev/null; then
    log "viewer screenshot (headless, Xvfb): docs/images/viewer.png"
    xvfb-run -a -s "-screen 0 1280x800x24" "$BUILD_DIR/fem_viewer" --frames 90 \
      --replay-drag auto --screenshot docs/images/viewer.png >/dev/null
  fi
}

# The run's folder gets the frames and the gif: a tracked file (docs/images/cantilever.gif) is
# written only by ./tutorial.sh docs, which exists to regenerate the docs.
sim() {
  local out=out/sim args=("$@") i
  for ((i = 0; i < ${#args[@]}; i++)); do
    [ "${args[i]}" = --out ] && out="${args[i + 1]:-}"
  done
  quiet_build
  log "simulating (VTK frames in $out/)"
  "$BUILD_DIR/fem_sim" --out "$out" --every 4 "$@"
  local pvd
  pvd=$(ls -t "$out"/*.pvd | head -n 1)
  log "rendering the frames to ${pvd%.pvd}.gif"
  fem_tools plots gif "$pvd" --out "${pvd%.pvd}.gif"
}

viewer() {
  quiet_build
  [ -x "$BUILD_DIR/fem_viewer" ] || { echo "fem_viewer was not built (see the CMake warning)" >&2; exit 1; }
  log "opening the viewer (space: pause, s: step, r: reset; drag the body with the mouse)"
  "$BUILD_DIR/fem_viewer" "$@"
}

viewer_bench() {
  quiet_build
  [ -x "$BUILD_DIR/fem_viewer" ] || { echo "fem_viewer was not built (see the CMake warning)" >&2; exit 1; }
  log "the viewer's frame rate per chapter, headless (Xvfb, Mesa's software OpenGL)"
  fem_tools runs viewer-fps --viewer "$BUILD_DIR/fem_viewer" --out results/viewer.json "$@"
}

# The book: every measurement the docs show, recorded on this machine in one sitting, then the
# docs regenerated from it and docs/data/book.json written (fem-tools docs book: the sources each
# chapter's data come from; ctest -L docs fails once a chapter's code differs from them).
book_quiet_check() {
  local load cores
  load=$(cut -d' ' -f1 /proc/loadavg 2>/dev/null || sysctl -n vm.loadavg | awk '{ print $2 }')
  cores=$(cores)
  # Busy: a 1-minute load above a quarter of the cores (one helper compiling is far above it).
  if awk -v l="$load" -v c="$cores" 'BEGIN { exit !(l > c / 4) }'; then
    echo "tutorial.sh book: the machine is not quiet (1-minute load $load on $cores cores); what runs:" >&2
    { ps -eo pcpu=,pid=,args= --sort=-pcpu 2>/dev/null || ps -Arco pcpu=,pid=,args=; } |
      awk '$1 > 2' | head -n 8 >&2
    echo "stop it and try again, or pass --busy to record anyway (the data will say so)" >&2
    exit 1
  fi
}

book_stage() {  # book_stage NAME COMMAND...: one timed stage, with the time left before it
  local name=$1 start=$SECONDS left=0 stage
  shift
  BOOK_STAGE=$((BOOK_STAGE + 1))
  for stage in "${BOOK_ORDER[@]:$((BOOK_STAGE - 1))}"; do left=$((left + ${BOOK_ESTIMATE[$stage]:-300})); done
  log "book [$BOOK_STAGE/${#BOOK_ORDER[@]}] $name: $((($SECONDS - BOOK_START) / 60)) min so far, about $((left / 60)) min left"
  "$@"
  BOOK_TIMES+=("$name=$((SECONDS - start))")
}

# replace_folder NEW OLD: NEW takes OLD's name, in two renames (the earlier folder is removed
# only after NEW has its name; a folder cannot be renamed over a full one in one step).
replace_folder() {
  local new=$1 old=$2
  rm -rf "$old.old"
  if [ -e "$old" ]; then mv "$old" "$old.old"; fi
  mv "$new" "$old"
  rm -rf "$old.old"
}

book() {
  [ "${1:-}" = "--busy" ] || book_quiet_check
  if [ -n "$(git status --porcelain -- chapters common apps)" ]; then
    echo "tutorial.sh book: chapters/, common/ or apps/ hold uncommitted changes; the book records" >&2
    echo "committed code only (commit them first):" >&2
    git status --short -- chapters common apps >&2
    exit 1
  fi
  quiet_build
  BOOK_ORDER=(meshes bench threads scaling regimes viewer docs)
  declare -gA BOOK_ESTIMATE=([meshes]=60 [bench]=240 [threads]=120 [scaling]=600 [regimes]=420
                             [viewer]=120 [docs]=900)
  local name seconds
  while read -r name seconds; do BOOK_ESTIMATE[$name]=$seconds; done \
    < <(fem_tools docs book estimate)
  BOOK_STAGE=0 BOOK_START=$SECONDS BOOK_TIMES=()
  local started
  started=$(date +%s)
  book_stage meshes meshes --large
  # The new run is recorded beside the earlier one and replaces it only once it is whole: a
  # bench stopped (Ctrl-C) or failed leaves results/book as it was.
  rm -rf results/book.new
  book_stage bench bench --out results/book.new
  replace_folder results/book.new results/book
  book_stage threads threads
  book_stage scaling scaling
  book_stage regimes regimes
  book_stage viewer viewer_bench
  book_stage docs docs results/book
  local IFS=,
  fem_tools docs book manifest --started "$started" --stages "${BOOK_TIMES[*]}"
  log "book: recorded in $(((SECONDS - BOOK_START) / 60)) min; commit docs/ (git status docs)"
}

meshes() {
  setup_python
  if ! "$VENV/bin/python" -c "import gmsh" 2>/dev/null; then
    echo "tutorial.sh meshes: gmsh is not installed in .venv (PyPI has no wheel of it for $(uname -s) $(uname -m)): new meshes cannot be generated here; the committed ones in meshes/ serve every chapter, test and benchmark" >&2
    exit 1
  fi
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
    plots) plots "$@" ;;
    compare) compare "$@" ;;
    variant) variant "$@" ;;
    diff) diff_variant "$@" ;;
    handin-check) handin_check "$@" ;;
    scaling) scaling "$@" ;;
    regimes) regimes "$@" ;;
    threads) threads "$@" ;;
    docs) docs "$@" ;;
    book) book "$@" ;;
    lessons) lessons ;;
    roofline) roofline "$@" ;;
    sim) sim "$@" ;;
    viewer) viewer "$@" ;;
    viewer-bench) viewer_bench "$@" ;;
    meshes) meshes "$@" ;;
    tools) setup_python; fem_tools "$@" ;;
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
