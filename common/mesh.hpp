// A linear tetrahedral mesh, read from a gmsh .msh file by the course's own reader
// (common/msh_read.hpp) or made from arrays.
#pragma once

#include <Eigen/Core>
#include <stdexcept>
#include <string>
#include <vector>

namespace fem {

struct TetMesh {
  Eigen::Matrix3Xd X;                     // rest positions, one column per node
  std::vector<Eigen::Vector4i> tets;      // positively oriented: det(Dm) > 0
  std::vector<Eigen::Vector3i> boundary;  // boundary triangles, outward normals
  std::string file;                       // where it came from (for messages and results)
  int reoriented_tets = 0;                // inverted tets flipped on load
  int dropped_nodes = 0;                  // nodes used by no tetrahedron, removed on load

  int num_nodes() const { return static_cast<int>(X.cols()); }
  int num_tets() const { return static_cast<int>(tets.size()); }
};

// Thrown for every problem with a mesh file; what() names the file and the problem.
struct MeshError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Loads the tetrahedra (gmsh element type 4) of an ASCII MSH 4.1 or 2.2 file (common/mesh_file.cpp,
// no gmsh SDK). Validates: the file's structure (common/msh_read.hpp), it has tetrahedra and no
// other volume element, coordinates are finite and at most 1e100, no tetrahedron is
// degenerate. Inverted tetrahedra are reoriented and counted; unused nodes dropped.
TetMesh load_mesh(const std::string& path);

// The file's own numbers of the nodes (in X's column order) and of the tetrahedra, so that an
// error names them as the file and gmsh's GUI do; empty for a mesh made in memory.
struct MeshTags {
  std::vector<std::size_t> node, tet;
};

// Builds a mesh from arrays (tests and generated scenes), with the same validation.
TetMesh make_mesh(Eigen::Matrix3Xd X, std::vector<Eigen::Vector4i> tets,
                  const std::string& name = "<memory>", const MeshTags& tags = {});

// Node pairs (i, j) sharing a tetrahedron, i and j included: the sparsity of the system.
std::vector<std::vector<int>> node_adjacency(const TetMesh& mesh);

// Boundary triangles: faces that belong to exactly one tetrahedron, oriented outward.
std::vector<Eigen::Vector3i> boundary_triangles(const std::vector<Eigen::Vector4i>& tets);

}  // namespace fem
