// Chapter 11's building block: an order of the nodes, and the scene renumbered in it.
//
// The same mesh numbered two ways is the same physics and the same algebra: the system
// matrix of the new numbering is P A P^T, the same eigenvalues, the same PCG iterations up
// to rounding. What changes is where things lie in memory. An element reads and writes its
// four nodes' rows of x, v, b and A; the SpMV reads x at the columns of each row. When the
// four nodes of an element have nearby numbers, those rows share cache lines and pages,
// and the pass over the elements walks memory forwards; when they are far apart (gmsh
// numbers the nodes of the surface first, then the interior), every element touches four
// distant places of a matrix far larger than the caches.
//
// Two classic orders, both computed once from the mesh:
// - reverse Cuthill-McKee (Cuthill & McKee 1969; reversed by George 1971): a breadth-first
//   search from a node at the end of the mesh (a pseudo-peripheral node, found as George &
//   Liu 1979 find it), neighbours in increasing degree. Each level of the search is a slice
//   across the body, so neighbours get numbers at most about one slice apart: a small
//   bandwidth;
// - a space-filling curve (Morton's Z-order on the rest positions): nodes close in space get
//   close numbers, whatever the connectivity.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "common/scene.hpp"

namespace fem::ch11 {

enum class Ordering {
  original,  // the mesh file's numbering, elements in the file's order (chapter 10's run)
  file,      // the mesh file's numbering, elements sorted along it (a file renumbered by
             // gmsh's computeRenumbering: fem-tools runs renumber-meshes)
  rcm,       // reverse Cuthill-McKee
  morton,    // Z-order curve on the rest positions
};
Ordering ordering_from_name(const std::string& name);  // throws std::invalid_argument
std::string ordering_name(Ordering ordering);

// A permutation of the nodes: new_of_old[old] = new, old_of_new[new] = old.
struct NodeOrder {
  std::vector<int> new_of_old, old_of_new;
  bool identity() const;
};

// old_of_new lists every node once; the order built from it.
NodeOrder order_from(std::vector<int> old_of_new);

std::vector<int> reverse_cuthill_mckee(const std::vector<std::vector<int>>& adjacency);
std::vector<int> morton_order(const Eigen::Matrix3Xd& X);
NodeOrder node_order(const TetMesh& mesh, Ordering ordering);

// The scene with node k renamed order.new_of_old[k] everywhere (positions, elements, boundary
// triangles, constraints, forces), and the elements sorted by their smallest new node (then
// the next ones), so that the element pass visits the nodes in order too. Each element keeps
// its own corner order, so its orientation (det Dm > 0) is kept. The identity order without
// sorting changes nothing.
Scene renumbered(const Scene& scene, const NodeOrder& order, bool sort_elements = true);

// How far apart the numbers of coupled nodes are: the measures the order is meant to shrink.
struct OrderQuality {
  long long bandwidth = 0;      // max |i - j| over coupled nodes i, j
  double profile = 0.0;         // sum over rows of (i - min j): the envelope, in nodes
  double element_spread = 0.0;  // mean over elements of (max - min) of its node numbers
};
OrderQuality order_quality(const TetMesh& mesh);

}  // namespace fem::ch11
