#include "common/mesh.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <sstream>

namespace fem {

namespace {

[[noreturn]] void fail(const std::string& file, const std::string& problem) {
  throw MeshError("mesh '" + file + "': " + problem);
}

double signed_volume6(const Eigen::Matrix3Xd& X, const Eigen::Vector4i& t) {
  Eigen::Matrix3d Dm;
  for (int i = 0; i < 3; ++i) Dm.col(i) = X.col(t[i + 1]) - X.col(t[0]);
  return Dm.determinant();
}

double longest_edge(const Eigen::Matrix3Xd& X, const Eigen::Vector4i& t) {
  double l = 0.0;
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j) l = std::max(l, (X.col(t[i]) - X.col(t[j])).norm());
  return l;
}

// How a message names node i and tetrahedron e: by the file's tags when the mesh came from a
// file (gmsh numbers from 1 and may skip numbers), else by position.
std::string node_name(const MeshTags& tags, Eigen::Index i) {
  if (static_cast<std::size_t>(i) < tags.node.size())
    return "node " + std::to_string(tags.node[static_cast<std::size_t>(i)]) + " (tag in the file)";
  return "node " + std::to_string(i);
}

std::string tet_name(const MeshTags& tags, std::size_t e) {
  if (e < tags.tet.size())
    return "tetrahedron " + std::to_string(tags.tet[e]) + " (element tag in the file)";
  return "tetrahedron " + std::to_string(e);
}

// Two tetrahedra on the same four nodes (a file's element listed twice, a second $Elements
// section) double that element's mass and stiffness without a word: refused by name.
void refuse_repeated_tets(const std::vector<Eigen::Vector4i>& tets, const std::string& name,
                          const MeshTags& tags) {
  std::vector<std::pair<std::array<int, 4>, std::size_t>> sorted(tets.size());
  for (std::size_t e = 0; e < tets.size(); ++e) {
    sorted[e] = {{tets[e][0], tets[e][1], tets[e][2], tets[e][3]}, e};
    std::sort(sorted[e].first.begin(), sorted[e].first.end());
  }
  std::sort(sorted.begin(), sorted.end());
  for (std::size_t k = 1; k < sorted.size(); ++k)
    if (sorted[k].first == sorted[k - 1].first)
      fail(name, tet_name(tags, sorted[k - 1].second) + " and " + tet_name(tags, sorted[k].second) +
                     " have the same four nodes");
}

// A tetrahedron's volume is a product of three coordinate differences: beyond 1e100 (the cube
// root of the largest double is 5.6e102) it overflows to inf, and a far node's edges make every
// tetrahedron on it look flat. Refused by the node, with its coordinate, before any volume.
void refuse_huge_coordinates(const Eigen::Matrix3Xd& X, const std::string& name,
                             const MeshTags& tags) {
  constexpr double kLargest = 1e100;
  for (Eigen::Index i = 0; i < X.cols(); ++i) {
    if (X.col(i).cwiseAbs().maxCoeff() <= kLargest) continue;
    std::ostringstream at;
    at << X(0, i) << ", " << X(1, i) << ", " << X(2, i);
    fail(name, node_name(tags, i) + " lies at (" + at.str() +
                   "): a coordinate beyond 1e100 overflows a tetrahedron's volume in double "
                   "precision; give the coordinates in metres");
  }
}

void check_arrays(const Eigen::Matrix3Xd& X, const std::vector<Eigen::Vector4i>& tets,
                  const std::string& name, const MeshTags& tags) {
  if (tets.empty())
    fail(name, "no tetrahedra (a file whose only physical group is a surface saves none)");
  if (!X.allFinite()) {
    Eigen::Index bad = 0;
    while (X.col(bad).allFinite()) ++bad;
    fail(name, node_name(tags, bad) + " has a NaN or infinite coordinate");
  }
  refuse_huge_coordinates(X, name, tags);
  for (std::size_t e = 0; e < tets.size(); ++e)
    for (int i = 0; i < 4; ++i)
      if (tets[e][i] < 0 || tets[e][i] >= X.cols())
        fail(name, tet_name(tags, e) + " refers to a missing node");
  refuse_repeated_tets(tets, name, tags);
}

// Drops the nodes no tetrahedron uses and renumbers the rest densely, in their order.
void drop_unused_nodes(const Eigen::Matrix3Xd& X, std::vector<Eigen::Vector4i>& tets,
                       TetMesh& mesh) {
  std::vector<int> new_index(static_cast<std::size_t>(X.cols()), -1);
  int used = 0;
  for (const auto& t : tets)
    for (int i = 0; i < 4; ++i)
      if (new_index[t[i]] < 0) new_index[t[i]] = 0;
  for (auto& n : new_index)
    if (n == 0) n = used++;
  mesh.dropped_nodes = static_cast<int>(X.cols()) - used;
  mesh.X.resize(3, used);
  for (Eigen::Index i = 0; i < X.cols(); ++i)
    if (new_index[i] >= 0) mesh.X.col(new_index[i]) = X.col(i);
  for (auto& t : tets)
    for (int i = 0; i < 4; ++i) t[i] = new_index[t[i]];
}

// Refuses flat tetrahedra and turns inverted ones (counted) so that det(Dm) > 0.
void orient_tets(std::vector<Eigen::Vector4i>& tets, TetMesh& mesh, const MeshTags& tags) {
  for (std::size_t e = 0; e < tets.size(); ++e) {
    auto& t = tets[e];
    const double vol6 = signed_volume6(mesh.X, t);
    const double l = longest_edge(mesh.X, t);
    // Relative to the element's size: a sliver whose volume is 1e-10 of a cube on
    // its longest edge is numerically flat and would make Dm singular.
    if (!(std::abs(vol6) > 1e-10 * l * l * l))
      fail(mesh.file,
           tet_name(tags, e) + " is degenerate (volume " + std::to_string(vol6 / 6.0) + ")");
    if (vol6 < 0.0) {
      std::swap(t[2], t[3]);
      ++mesh.reoriented_tets;
    }
  }
}

}  // namespace

TetMesh make_mesh(Eigen::Matrix3Xd X, std::vector<Eigen::Vector4i> tets, const std::string& name,
                  const MeshTags& tags) {
  check_arrays(X, tets, name, tags);
  TetMesh mesh;
  mesh.file = name;
  drop_unused_nodes(X, tets, mesh);
  orient_tets(tets, mesh, tags);
  mesh.tets = std::move(tets);
  mesh.boundary = boundary_triangles(mesh.tets);
  return mesh;
}

std::vector<std::vector<int>> node_adjacency(const TetMesh& mesh) {
  std::vector<std::vector<int>> adj(static_cast<std::size_t>(mesh.num_nodes()));
  for (const auto& t : mesh.tets)
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b) adj[t[a]].push_back(t[b]);
  for (auto& row : adj) {
    std::sort(row.begin(), row.end());
    row.erase(std::unique(row.begin(), row.end()), row.end());
  }
  return adj;
}

std::vector<Eigen::Vector3i> boundary_triangles(const std::vector<Eigen::Vector4i>& tets) {
  // Faces of a positively oriented tet (0,1,2,3), each seen from outside counter-clockwise.
  static constexpr std::array<std::array<int, 3>, 4> faces = {
      {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}}};
  std::map<std::array<int, 3>, std::pair<Eigen::Vector3i, int>> seen;
  for (const auto& t : tets) {
    for (const auto& f : faces) {
      const Eigen::Vector3i tri(t[f[0]], t[f[1]], t[f[2]]);
      std::array<int, 3> key = {tri[0], tri[1], tri[2]};
      std::sort(key.begin(), key.end());
      auto [it, inserted] = seen.try_emplace(key, tri, 0);
      ++it->second.second;
    }
  }
  std::vector<Eigen::Vector3i> out;
  for (const auto& [key, value] : seen)
    if (value.second == 1) out.push_back(value.first);
  return out;
}

}  // namespace fem
