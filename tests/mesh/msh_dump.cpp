// msh_dump FILE: what the course's reader reads from a .msh file (common/msh_read.hpp), in the
// order gmsh's API gives it, for tests/scripts/compare_meshes_with_gmsh.py to hold against
// gmsh's own reading: "nodes N", then "tag x y z" a node (by tag, every digit of each double),
// "tets T", then "tag node node node node" a tetrahedron (the file's node tags).
#include <cstdio>
#include <cstring>

#include "common/mesh.hpp"
#include "common/msh_read.hpp"

int main(int argc, char** argv) {
  if (argc != 2 || std::strcmp(argv[1], "--help") == 0) {
    std::printf(
        "usage: msh_dump FILE.msh\n\nPrints the nodes (tag x y z, by tag, %%.17g) and the linear "
        "tetrahedra (tag and node tags, in gmsh's order) that the course's reader reads.\n");
    return argc == 2 ? 0 : 2;
  }
  try {
    const fem::MshFile file = fem::read_msh_file(argv[1]);
    std::printf("nodes %zu\n", file.node_tags.size());
    for (std::size_t i = 0; i < file.node_tags.size(); ++i)
      std::printf("%llu %.17g %.17g %.17g\n", static_cast<unsigned long long>(file.node_tags[i]),
                  file.xyz[3 * i], file.xyz[3 * i + 1], file.xyz[3 * i + 2]);
    std::printf("tets %zu\n", file.tets.size());
    for (std::size_t e = 0; e < file.tets.size(); ++e) {
      std::printf("%lld", static_cast<long long>(file.tet_tags[e]));
      for (const int node : file.tets[e])
        std::printf(" %llu", static_cast<unsigned long long>(file.node_tags[node]));
      std::printf("\n");
    }
  } catch (const fem::MeshError& e) {
    std::fprintf(stderr, "msh_dump: %s\n", e.what());
    return 1;
  }
  return 0;
}
