#!/bin/sh
# A chapter folder with an unusable name (a newline, a space, a ';') stops configure with the
# folder named (cmake/chapter_names.cmake), and usable names pass: a newline in a name once
# made configure write a build.ninja that ninja could not lex.
# usage: test_chapter_names.sh CMAKE SOURCE_DIR SCRATCH
set -u
cmake="$1" check="$2/cmake/chapter_names.cmake" scratch="$3/chapter_names"
rm -rf "$scratch" && mkdir -p "$scratch/chapters/06_custom_pcg" "$scratch/chapters/notes"
touch "$scratch/chapters/06_custom_pcg/stepper.hpp" "$scratch/chapters/registry.cmake"
failed=0
run() { "$cmake" -DCHAPTERS_DIR="$scratch/chapters" -P "$check" 2>&1; }

if ! out=$(run); then
  printf "%s\n" "FAIL: usable names refused: $out"; failed=1
fi
# Each bad name, then the name the message must show (a newline spelled \n; CMake wraps
# its message at spaces, which the check joins again).
check_refused() {
  bad="$1" shown="$2"
  mkdir "$scratch/chapters/$bad" && touch "$scratch/chapters/$bad/stepper.cpp"
  if out=$(run); then
    printf "%s\n" "FAIL: configure accepted chapters/$shown"; failed=1
  elif ! printf '%s' "$out" | tr "\n" " " | tr -s " " | grep -qF "chapters/$shown:"; then
    printf "%s\n" "FAIL: the refusal does not name chapters/$shown: $out"; failed=1
  else
    printf "%s\n" "ok: chapters/$shown refused"
  fi
  rm -rf "$scratch/chapters/$bad"
}
check_refused "06_x
" '06_x\n'
check_refused "06_my variant" "06_my variant"
check_refused "06_a;b" "06_a... (a name holding ';')"
check_refused "6_short" "6_short"
check_refused "06_x-y" "06_x-y"
rm -rf "$scratch"
[ "$failed" -eq 0 ] && printf "%s\n" "PASS: every unusable chapter folder name is refused by name"
exit "$failed"
