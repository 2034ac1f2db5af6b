#!/usr/bin/env bash
# What `cmake --install` ships (cmake/install.cmake), checked from the outside:
#  - at most 15 headers, each compiling alone with the standard library only;
#  - no symbol of the course in the archives (a lesson, a work count, a kernel timed alone, the
#    course's list) nor of its I/O (JSON, the command line, VTK, the machine record), read with
#    nm -C: what the archives hold, whatever their members are called;
#  - no compile option of ours in the exported targets (OpenMP link-only), the instruction set
#    recorded in the config;
#  - a consumer in another standard library mode (-D_GLIBCXX_DEBUG) does not link, naming it,
#    while the same consumer in the library's mode links and runs.
# Usage: installed_package.sh BUILD_DIR WORK_DIR
set -euo pipefail
build=$1 work=$(realpath -m "$2")
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
rm -rf "$work" && mkdir -p "$work"
cmake --install "$build" --prefix "$work/prefix" >"$work/install.log"
compiler=$(sed -n 's/^CMAKE_CXX_COMPILER:[A-Z]*=//p' "$build/CMakeCache.txt")
fail() { echo "FAIL: $*" >&2; exit 1; }

mapfile -t headers < <(cd "$work/prefix/include" && find . -name '*.hpp' | sort)
echo "installed headers: ${#headers[@]} (${headers[*]})"
((${#headers[@]} >= 1 && ${#headers[@]} <= 15)) || fail "${#headers[@]} headers installed"
for header in "${headers[@]}"; do
  echo "#include <${header#./}>" | "$compiler" -std=c++17 -Wall -Wextra -Wpedantic -Werror \
    -fsyntax-only -I"$work/prefix/include" -x c++ - ||
    fail "$header does not compile alone"
done

# The course's symbols (chapters/course.hpp, chapters/work.hpp's hooks, common/lesson.hpp) and
# its I/O's (common/json, cli, vtk, machine_record, run_lock, atomic_file, build_info), defined
# or referenced.
course='fem::Lesson\b|fem::CourseChapter|fem::detail::CourseHooks|course_chapters|discovered_course|fem::PartKernel|fem::ChapterWork|count_work|executed_work|solve_kernels'
io='nlohmann|json_text|fem::ArgParser|fem::UsageError|write_file_atomically|fem::VtkSeries|fem::RunLock|fem::MachineRecord|fem::build_info\('
# The patterns find the course where it is: in its own archive (so a renamed symbol that they
# no longer match fails here, not silently below).
course_symbols=$(nm -C "$build/libfem_chapters.a" 2>/dev/null)
for what in "fem::Lesson" "course_chapters" "count_work" "fem::PartKernel"; do
  grep -qF "$what" <<<"$course_symbols" ||
    fail "the course's archive holds no $what: the symbol check below no longer finds the course"
done
for archive in "$work"/prefix/lib/*.a; do
  symbols=$(nm -C "$archive" 2>/dev/null)
  echo "$(basename "$archive"): $(wc -c <"$archive") bytes, $(ar t "$archive" | wc -l) objects," \
    "$(grep -c ' [TtWwVvBbDdRr] ' <<<"$symbols") defined symbols"
  if found=$(grep -E "$course|$io" <<<"$symbols"); then
    sort -u <<<"$found" | head -n 20 >&2
    fail "$(basename "$archive") holds the course's code (lessons, work counts, kernels alone) or its I/O"
  fi
done
grep -q ' T fem::chapters()' <<<"$(nm -C "$work/prefix/lib/libfem_steppers.a")" ||
  fail "libfem_steppers.a defines no fem::chapters(): the registry is not in the library"

targets=$(cat "$work"/prefix/lib/cmake/femcourse/femcourse-targets*.cmake)
if grep -E "INTERFACE_COMPILE_OPTIONS|fopenmp|march" <<<"$targets"; then
  fail "the exported targets pass compile options to their consumers"
fi
if grep -o '.\{10\}OpenMP::OpenMP_CXX' <<<"$targets" | grep -v 'LINK_ONLY:OpenMP'; then
  fail "OpenMP is more than a link dependency of the exported targets"
fi
grep -o 'set(femcourse_CPU_FLAGS "[^"]*")' "$work/prefix/lib/cmake/femcourse/femcourse-config.cmake" ||
  fail "the config records no instruction set"

probe() {  # NAME CXX_FLAGS
  cmake -S "$here/abi_probe" -B "$work/$1" -G Ninja -DCMAKE_BUILD_TYPE=Release \
    ${compiler:+"-DCMAKE_CXX_COMPILER=$compiler"} "-DCMAKE_PREFIX_PATH=$work/prefix" \
    "-DCMAKE_CXX_FLAGS=$2" >"$work/$1.configure.log"
  cmake --build "$work/$1" >"$work/$1.build.log" 2>&1
}
probe same "" || { cat "$work/same.build.log" >&2; fail "the consumer in the library's mode"; }
"$work/same/probe"
grep -q -- "-fopenmp" "$work/same/build.ninja" && fail "-fopenmp reached the consumer's flags"
if probe debug "-D_GLIBCXX_DEBUG"; then
  fail "a consumer built with -D_GLIBCXX_DEBUG linked against the library"
fi
grep -q "femcourse::glibcxx_debug::Body" "$work/debug.build.log" ||
  fail "the refused link does not name the mode (femcourse::glibcxx_debug)"
echo "a -D_GLIBCXX_DEBUG consumer is refused at link time: $(grep -m1 -o 'undefined reference to .femcourse::glibcxx_debug::[^(]*' "$work/debug.build.log")"
echo "PASS: the installed package"
