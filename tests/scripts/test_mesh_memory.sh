#!/bin/bash
# No program sizes memory by a mesh file's header before checking it against the file's size
# (common/msh_read.hpp): under `ulimit -v` at what the program needs to run the committed test
# mesh plus twice the bad file's size and a fixed margin, a file of a few hundred bytes whose
# header claims a billion nodes or elements is refused with the count named, not a
# std::bad_alloc (a 327-byte file once took 20 GiB of the machine before gmsh gave up).
# usage: test_mesh_memory.sh SOURCE_DIR SCRATCH PROGRAM...   (fem_sim, fem_bench, fem_lessons)
set -u
source_dir="$1" scratch="$2/mesh_memory"
shift 2
programs=()
for program in "$@"; do programs+=("$(realpath "$program")"); done  # before the cd below
rm -rf "$scratch" && mkdir -p "$scratch" && cd "$scratch" || exit 1
margin_kb=$((64 * 1024))
failed=0

cube22() {  # MSH 2.2 unit cube; $1 the node count, $2 the element count its headers claim
  printf '$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n%s\n' "$1"
  printf '1 0 0 0\n2 1 0 0\n3 0 1 0\n4 1 1 0\n5 0 0 1\n6 1 0 1\n7 0 1 1\n8 1 1 1\n$EndNodes\n'
  printf '$Elements\n%s\n1 4 2 0 1 1 2 4 8\n2 4 2 0 1 1 2 8 6\n3 4 2 0 1 1 3 8 4\n' "$2"
  printf '4 4 2 0 1 1 3 7 8\n5 4 2 0 1 1 5 6 8\n6 4 2 0 1 1 5 8 7\n$EndElements\n'
}
tet41() {  # MSH 4.1 single tetrahedron; $1 the node count, $2 the element count claimed
  printf '$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 %s 1 4\n3 1 0 4\n1\n2\n3\n4\n' "$1"
  printf '0 0 0\n1 0 0\n0 1 0\n0 0 1\n$EndNodes\n$Elements\n1 %s 1 1\n3 1 4 1\n' "$2"
  printf '1 1 2 3 4\n$EndElements\n'
}
nodedata() {  # a $NodeData section claiming $1 entries after the cube
  cube22 8 6
  printf '$NodeData\n1\n"d"\n1\n0.0\n3\n0\n1\n%s\n1 0.5\n$EndNodeData\n' "$1"
}
cube22 1000000000 6 >nodes22.msh
nodedata 1000000000 >nodedata22.msh
cube22 8 1000000000 >elements22.msh
tet41 1000000000 1 >nodes41.msh
tet41 4 1000000000 >elements41.msh

command_for() {  # the program's command line on mesh $2
  case "$1" in
    */fem_sim) echo "$1 --mesh $2 --steps 1 --every 0 --out sim" ;;
    */fem_bench) echo "$1 --mesh $2 --steps 1 --warmup 1 --chapters 01 --no-solvers --no-json" ;;
    */fem_lessons) echo "$1 multigrid --mesh $2 --steps 1" ;;
  esac
}

# The least of a ladder of limits (KiB) under which the program runs the committed test mesh.
needed_kb() {
  local kb
  for kb in 262144 393216 524288 786432 1048576 1572864 2097152 4194304; do
    if (ulimit -v "$kb" && $(command_for "$1" "$source_dir/meshes/test_beam.msh")) >/dev/null 2>&1
    then
      echo "$kb"
      return
    fi
  done
  echo 0
}

for program in "${programs[@]}"; do
  base_kb=$(needed_kb "$program")
  if [ "$base_kb" -eq 0 ]; then
    echo "FAIL: $(basename "$program") does not run the test mesh under 4 GiB"; failed=1; continue
  fi
  for file in nodes22 elements22 nodes41 elements41 nodedata22; do
    limit_kb=$((base_kb + 2 * $(stat -c %s "$file.msh") / 1024 + margin_kb))
    out=$( (ulimit -v "$limit_kb" && $(command_for "$program" "$file.msh")) 2>&1)
    if printf '%s' "$out" | grep -q "declares 1000000000 \(nodes\|elements\|entries\), more than the file can hold"; then
      echo "ok: $(basename "$program") refuses $file.msh under ulimit -v $limit_kb"
    else
      echo "FAIL: $(basename "$program") on $file.msh under ulimit -v $limit_kb: $out"; failed=1
    fi
  done
done
[ "$failed" -eq 0 ] && echo "PASS: no program allocates by a header it has not checked"
exit "$failed"
