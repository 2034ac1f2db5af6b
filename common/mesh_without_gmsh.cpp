// load_mesh for a program linked without the gmsh reader (femcourse::simulator alone). Part of
// fem_fallbacks (CMakeLists.txt): a program that links fem_mesh_gmsh gets the reader instead.
#include "common/mesh.hpp"

namespace fem {

TetMesh load_mesh(const std::string& path) {
  throw MeshError("mesh '" + path +
                  "': this program reads no mesh files: link the gmsh reader "
                  "(femcourse::mesh_gmsh, or fem_mesh_gmsh inside the repository)");
}

}  // namespace fem
