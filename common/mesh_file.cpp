// load_mesh: a .msh file read by the course's own reader (common/msh_read.cpp), so that the
// library and every program read meshes without the gmsh SDK; gmsh stays the course's mesher
// (meshes/generate.py, through its Python package).
#include "common/mesh.hpp"
#include "common/msh_read.hpp"

namespace fem {
namespace {

// Any volume element other than the 4-node tetrahedron (gmsh type 4) is refused, with the
// types and counts found: loading the tetrahedra alone would drop the rest of the body
// silently (tetrahedra beside hexahedra), and second-order tetrahedra (10 nodes) are another
// element than the linear one the steppers integrate.
void refuse_other_volume_elements(const std::string& path, const MshFile& file) {
  std::string found;
  for (const auto& [type, named] : file.other_volume)
    found += (found.empty() ? "" : ", ") + std::to_string(named.second) + " " + named.first +
             " (gmsh type " + std::to_string(type) + ", " +
             named.first.substr(named.first.find(' ') + 1) + " nodes)";
  if (found.empty()) return;
  throw MeshError("mesh '" + path +
                  "': holds volume elements other than 4-node tetrahedra: " + found +
                  ". The programs take linear tetrahedra only: in gmsh, mesh the volume with "
                  "tetrahedra only (no recombination, Mesh.RecombineAll = 0) at first order "
                  "(gmsh.model.mesh.setOrder(1), or Mesh.ElementOrder = 1), and save again");
}

}  // namespace

TetMesh load_mesh(const std::string& path) {
  const MshFile file = read_msh_file(path);
  refuse_other_volume_elements(path, file);
  if (file.node_tags.empty())
    throw MeshError("mesh '" + path + "': not a mesh: its $Nodes section holds no nodes");
  // Node i is the node with the i-th smallest tag: the file's numbering, also when the file
  // lists the nodes entity by entity in another order (a mesh renumbered by gmsh's
  // computeRenumbering, chapter 11).
  const auto nodes = static_cast<Eigen::Index>(file.node_tags.size());
  Eigen::Matrix3Xd X = Eigen::Map<const Eigen::Matrix3Xd>(file.xyz.data(), 3, nodes);
  std::vector<Eigen::Vector4i> tets;
  tets.reserve(file.tets.size());
  for (const auto& t : file.tets) tets.emplace_back(t[0], t[1], t[2], t[3]);
  MeshTags tags;
  tags.node.assign(file.node_tags.begin(), file.node_tags.end());
  tags.tet.assign(file.tet_tags.begin(), file.tet_tags.end());
  return make_mesh(std::move(X), std::move(tets), path, tags);
}

}  // namespace fem
