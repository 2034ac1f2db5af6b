#!/bin/bash
# Two build-and-run commands at once never build in one folder together (tutorial.sh's build
# lock): while another process holds the build folder's lock, `./tutorial.sh build` says that it
# waits, and its build starts only after the lock is released (the order of the two processes'
# marks, never a time).
# usage: test_build_lock.sh SOURCE_DIR BUILD_DIR
set -u
root="$1" build_dir="$2"
preset=$(basename "$build_dir")
order=$(mktemp) out=$(mktemp) bin=$(mktemp -d)
trap 'rm -f "$order" "$out"; rm -rf "$bin"' EXIT

# build_after_holder HOW PATH HOLDER...: the holder (a command that takes the lock, marks
# "held", waits, marks "released" and lets go) runs; then ./tutorial.sh build with that PATH must
# say that it waits and build only after the release.
build_after_holder() {
  local how=$1 path=$2 holder status
  shift 2
  : >"$order"
  "$@" &
  holder=$!
  while ! grep -q held "$order"; do sleep 0.1; done
  PATH="$path" PRESET="$preset" FEM_SKIP_PACKAGES=1 "$root/tutorial.sh" build >"$out" 2>&1
  status=$?
  echo built >>"$order"
  wait "$holder"
  if [ "$status" -ne 0 ]; then
    echo "FAIL ($how): ./tutorial.sh build failed:"; cat "$out"; exit 1
  fi
  if ! grep -q "another command is building in build/$preset: waiting for its build to end" "$out"; then
    echo "FAIL ($how): ./tutorial.sh build did not say that it waits:"; cat "$out"; exit 1
  fi
  if [ "$(tr '\n' ' ' <"$order")" != "held released built " ]; then
    echo "FAIL ($how): the build did not wait for the lock: $(tr '\n' ' ' <"$order")"; exit 1
  fi
}

build_after_holder flock "$PATH" flock "$build_dir/.build.lock" \
  sh -c "echo held >>'$order'; sleep 3; echo released >>'$order'"
echo "PASS: the second build waited for the first, and said so"

# The same without flock (macOS): the lock is a directory holding its owner's process id.
IFS=: read -r -a dirs <<<"$PATH"
for dir in "${dirs[@]}"; do
  for tool in "$dir"/*; do
    name=$(basename "$tool")
    [ "$name" = flock ] || [ -e "$bin/$name" ] || [ ! -x "$tool" ] || ln -s "$tool" "$bin/$name"
  done
done
lock="$build_dir/.build.lock.d"
build_after_holder mkdir "$bin" sh -c "mkdir '$lock' && echo \$\$ >'$lock/pid' && echo held >>'$order' && sleep 3 && echo released >>'$order' && rm -rf '$lock'"
[ ! -e "$lock" ] || { echo "FAIL (mkdir): the lock was left behind"; exit 1; }
echo "PASS: without flock too (the mkdir lock)"
