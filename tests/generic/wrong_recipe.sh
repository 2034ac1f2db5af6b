#!/bin/sh
# wrong_recipe.sh COMPILER SOURCE_DIR EIGEN_INCLUDE_DIRS: each mistake of wrong_recipe.cpp fails
# to compile with one error, the sentence of check_recipe that names its role and member.
compiler=$1 root=$2 eigen=$(echo "$3" | cut -d';' -f1)
status=0
check() {
  mistake=$1 sentence=$2
  output=$("$compiler" -std=c++17 -fsyntax-only -DMISTAKE="$mistake" -I"$root" -I"$eigen" \
    "$root/tests/generic/wrong_recipe.cpp" 2>&1) && {
    echo "FAIL: mistake $mistake compiled"
    status=1
    return
  }
  errors=$(printf '%s\n' "$output" | grep -c 'error:')
  printf '%s\n' "$output" | grep 'error:'
  if [ "$errors" -ne 1 ] || ! printf '%s\n' "$output" | grep -qF "$sentence"; then
    echo "FAIL: mistake $mistake: $errors errors, expected one saying \"$sentence\""
    status=1
  else
    echo "ok: mistake $mistake fails with one sentence"
  fi
}
check 1 "Recipe: no Guess (using Guess = ...;)"
check 2 "Preconditioner part: not a ch08::PreconditionerPart (prepare(A), apply(r, s))"
exit $status
