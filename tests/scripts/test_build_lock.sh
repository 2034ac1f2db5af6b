#!/bin/bash
# Two build-and-run commands at once never build in one folder together (tutorial.sh's build
# lock): while another process holds the build folder's lock, `./tutorial.sh build` says that it
# waits, and its build starts only after the lock is released (the order of the two processes'
# marks, never a time).
# usage: test_build_lock.sh SOURCE_DIR BUILD_DIR
set -u
root="$1" build_dir="$2"
preset=$(basename "$build_dir")
order=$(mktemp) out=$(mktemp)
trap 'rm -f "$order" "$out"' EXIT
# The holder takes the lock, says so, and releases it after a mark; the build must come after.
flock "$build_dir/.build.lock" sh -c "echo held >>'$order'; sleep 3; echo released >>'$order'" &
holder=$!
while ! grep -q held "$order"; do sleep 0.1; done
PRESET="$preset" FEM_SKIP_PACKAGES=1 "$root/tutorial.sh" build >"$out" 2>&1
status=$?
echo built >>"$order"
wait "$holder"
if [ "$status" -ne 0 ]; then
  echo "FAIL: ./tutorial.sh build failed:"; cat "$out"; exit 1
fi
if ! grep -q "another command is building in build/$preset: waiting for its build to end" "$out"; then
  echo "FAIL: ./tutorial.sh build did not say that it waits:"; cat "$out"; exit 1
fi
if [ "$(tr '\n' ' ' <"$order")" != "held released built " ]; then
  echo "FAIL: the build did not wait for the lock: $(tr '\n' ' ' <"$order")"; exit 1
fi
echo "PASS: the second build waited for the first, and said so"
