// The gmsh file reader: the only part of the core that needs the gmsh SDK (GPL-2.0-or-later
// with exceptions), built as its own optional target (fem_mesh_gmsh, femcourse::mesh_gmsh) so
// that the simulator library does not link gmsh. Without it, load_mesh throws
// (common/mesh_without_gmsh.cpp).
#include <gmsh.h>

#include <algorithm>
#include <mutex>
#include <numeric>
#include <unordered_map>

#include "common/cli.hpp"
#include "common/mesh.hpp"
#include "common/msh_check.hpp"

// Named by fem_mesh_gmsh's link option -u (CMakeLists.txt): it pulls this file into every
// program that links the reader, so that its load_mesh wins over fem_fallbacks'.
extern "C" void fem_mesh_gmsh_reader() {}

namespace {
const bool notice_set = (fem::help_notice =
                             "This program links the gmsh SDK (GPL-2.0-or-later with exceptions): "
                             "its own code is MIT, a binary of it passed on is a combined work "
                             "under the GPL's terms (README.md, License).",
                         true);
}  // namespace

namespace fem {
namespace {

[[noreturn]] void fail(const std::string& file, const std::string& problem) {
  throw MeshError("mesh '" + file + "': " + problem);
}

// gmsh keeps global state: initialize once, clear before each file.
std::mutex& gmsh_mutex() {
  static std::mutex m;
  return m;
}

bool gmsh_initialized = false;

void ensure_gmsh_initialized() {
  if (gmsh_initialized) return;
  gmsh::initialize(0, nullptr, /*readConfigFiles=*/false, /*run=*/false);
  gmsh::option::setNumber("General.Terminal", 0);
  gmsh::option::setNumber("General.Verbosity", 0);
  gmsh_initialized = true;
}

// After a parse error gmsh stays "busy" and answers nothing more: start it afresh.
void reset_gmsh() {
  gmsh::finalize();
  gmsh_initialized = false;
}

// Any volume element other than the 4-node tetrahedron (gmsh type 4) is refused, with the
// types and counts found: loading the tetrahedra alone would drop the rest of the body
// silently (tetrahedra beside hexahedra), and second-order tetrahedra (10 nodes) are another
// element than the linear one the steppers integrate.
void refuse_other_volume_elements(const std::string& path) {
  std::vector<int> types;
  gmsh::model::mesh::getElementTypes(types, 3);
  std::string found;
  for (const int type : types) {
    if (type == 4) continue;
    std::vector<std::size_t> tags, nodes;
    gmsh::model::mesh::getElementsByType(type, tags, nodes);
    std::string name;
    int dim = 0, order = 0, num_nodes = 0, primary = 0;
    std::vector<double> local;
    gmsh::model::mesh::getElementProperties(type, name, dim, order, num_nodes, local, primary);
    found += (found.empty() ? "" : ", ") + std::to_string(tags.size()) + " " + name +
             " (gmsh type " + std::to_string(type) + ", " + std::to_string(num_nodes) + " nodes)";
  }
  if (found.empty()) return;
  gmsh::clear();
  fail(path, "holds volume elements other than 4-node tetrahedra: " + found +
                 ". The programs take linear tetrahedra only: in gmsh, mesh the volume with "
                 "tetrahedra only (no recombination, Mesh.RecombineAll = 0) at first order "
                 "(gmsh.model.mesh.setOrder(1), or Mesh.ElementOrder = 1), and save again");
}

}  // namespace

TetMesh load_mesh(const std::string& path) {
  // Before gmsh: it sizes its arrays by the file's header counts and keeps the last of two
  // nodes with one tag, so a cut or corrupt file is refused here with its cause.
  check_msh_file(path);
  std::lock_guard<std::mutex> lock(gmsh_mutex());
  ensure_gmsh_initialized();
  gmsh::clear();
  try {
    gmsh::open(path);
  } catch (const std::exception& e) {
    reset_gmsh();
    fail(path, std::string("gmsh cannot read it as a mesh file: ") + e.what());
  } catch (...) {
    reset_gmsh();
    fail(path, "gmsh cannot read it as a mesh file");
  }

  refuse_other_volume_elements(path);
  std::vector<std::size_t> node_tags;
  std::vector<double> coords, params;
  gmsh::model::mesh::getNodes(node_tags, coords, params, -1, -1, false, false);
  std::vector<std::size_t> elem_tags, elem_nodes;
  gmsh::model::mesh::getElementsByType(4, elem_tags, elem_nodes);  // 4 = linear tetrahedron
  gmsh::clear();
  if (node_tags.empty()) fail(path, "not a mesh: gmsh found no nodes in it");

  // Node i is the node with the i-th smallest tag: the file's numbering, also when gmsh lists
  // the nodes entity by entity in another order (a mesh renumbered by computeRenumbering,
  // chapter 11). A mesh gmsh generated lists them in tag order already.
  std::vector<std::size_t> by_tag(node_tags.size());
  std::iota(by_tag.begin(), by_tag.end(), std::size_t{0});
  std::sort(by_tag.begin(), by_tag.end(),
            [&](std::size_t a, std::size_t b) { return node_tags[a] < node_tags[b]; });
  std::unordered_map<std::size_t, int> index_of_tag;
  index_of_tag.reserve(node_tags.size());
  MeshTags tags;
  tags.node.resize(node_tags.size());
  Eigen::Matrix3Xd X(3, static_cast<Eigen::Index>(node_tags.size()));
  for (std::size_t i = 0; i < by_tag.size(); ++i) {
    const std::size_t k = by_tag[i];
    index_of_tag.emplace(node_tags[k], static_cast<int>(i));
    tags.node[i] = node_tags[k];
    X.col(static_cast<Eigen::Index>(i)) << coords[3 * k], coords[3 * k + 1], coords[3 * k + 2];
  }
  std::vector<Eigen::Vector4i> tets(elem_tags.size());
  for (std::size_t e = 0; e < elem_tags.size(); ++e) {
    for (int k = 0; k < 4; ++k) {
      const auto it = index_of_tag.find(elem_nodes[4 * e + k]);
      if (it == index_of_tag.end())
        fail(path, "tetrahedron " + std::to_string(elem_tags[e]) +
                       " (element tag in the file) refers to an undefined node " +
                       std::to_string(elem_nodes[4 * e + k]));
      tets[e][k] = it->second;
    }
  }
  tags.tet = std::move(elem_tags);
  return make_mesh(std::move(X), std::move(tets), path, tags);
}

}  // namespace fem
