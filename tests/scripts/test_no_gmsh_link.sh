#!/bin/bash
# No program nor test of the build links the gmsh SDK (the course reads its meshes itself,
# common/msh_read.cpp): ldd of every executable in the build folder and its tests/ folder names
# no libgmsh, and no archive of the library has a symbol of gmsh's API.
# usage: test_no_gmsh_link.sh BUILD_DIR
set -u
build="$1"
programs=0 archives=0 failed=0
while IFS= read -r -d '' file; do
  head -c 4 "$file" | grep -q 'ELF' || continue
  programs=$((programs + 1))
  if ! libraries=$(ldd "$file" 2>&1); then
    echo "FAIL: ldd $file: $libraries"
    failed=1
  elif grep -i gmsh <<<"$libraries"; then
    echo "FAIL: $file links the gmsh SDK"
    failed=1
  fi
done < <(find "$build" "$build/tests" -maxdepth 1 -type f -perm -u+x -print0)
for archive in "$build"/libfem_*.a; do
  [ -e "$archive" ] || continue
  archives=$((archives + 1))
  if nm -C "$archive" 2>/dev/null | grep -E ' gmsh::|gmsh\.h'; then
    echo "FAIL: $archive refers to gmsh's API"
    failed=1
  fi
done
if [ ! -x "$build/fem_sim" ] || [ "$programs" -lt 5 ] || [ "$archives" -lt 3 ]; then
  echo "FAIL: $programs programs and $archives archives found in $build: not a built folder"
  exit 1
fi
[ "$failed" = 0 ] || exit 1
echo "PASS: $programs programs and tests, none links libgmsh (ldd); $archives archives, none refers to gmsh's API (nm)"
