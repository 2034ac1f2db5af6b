// Chapter 11: the orders of the nodes (see node_order.hpp) and the renumbered scene.
#include "chapters/11_node_order/node_order.hpp"

#include <algorithm>
#include <array>
#include <numeric>
#include <stdexcept>

namespace fem::ch11 {

Ordering ordering_from_name(const std::string& name) {
  if (name == "original") return Ordering::original;
  if (name == "file") return Ordering::file;
  if (name == "rcm") return Ordering::rcm;
  if (name == "morton") return Ordering::morton;
  throw std::invalid_argument("node order '" + name + "': original, file, rcm or morton");
}

std::string ordering_name(Ordering ordering) {
  switch (ordering) {
    case Ordering::original:
      return "original";
    case Ordering::file:
      return "file";
    case Ordering::rcm:
      return "rcm";
    case Ordering::morton:
      return "morton";
  }
  return "?";
}

bool NodeOrder::identity() const {
  for (std::size_t k = 0; k < old_of_new.size(); ++k)
    if (old_of_new[k] != static_cast<int>(k)) return false;
  return true;
}

NodeOrder order_from(std::vector<int> old_of_new) {
  NodeOrder order;
  order.new_of_old.assign(old_of_new.size(), -1);
  for (std::size_t k = 0; k < old_of_new.size(); ++k) {
    const int old = old_of_new[k];
    if (old < 0 || old >= static_cast<int>(old_of_new.size()) || order.new_of_old[old] != -1)
      throw std::invalid_argument("node order: not a permutation of the nodes");
    order.new_of_old[old] = static_cast<int>(k);
  }
  order.old_of_new = std::move(old_of_new);
  return order;
}

namespace {

int degree(const std::vector<std::vector<int>>& adjacency, int i) {
  return static_cast<int>(adjacency[i].size()) - 1;  // the row lists i itself
}

struct Search {
  std::size_t last_level;  // where the last level begins in the order
  int levels;              // how many levels: the eccentricity of the start, plus one
};

// Breadth-first search from `start` over the unvisited nodes, neighbours in increasing
// degree (then number): the Cuthill-McKee order of start's component, appended to `order`.
Search breadth_first(const std::vector<std::vector<int>>& adjacency, int start,
                     std::vector<char>& visited, std::vector<int>& order) {
  Search search{order.size(), 0};
  std::size_t head = order.size();
  order.push_back(start);
  visited[start] = 1;
  std::vector<int> next;
  while (head < order.size()) {
    search.last_level = head;
    ++search.levels;
    const std::size_t level_end = order.size();
    for (; head < level_end; ++head) {
      next.clear();
      for (const int j : adjacency[order[head]])
        if (!visited[j]) next.push_back(j);
      std::sort(next.begin(), next.end(), [&](int a, int b) {
        return std::make_pair(degree(adjacency, a), a) < std::make_pair(degree(adjacency, b), b);
      });
      for (const int j : next) visited[j] = 1;
      order.insert(order.end(), next.begin(), next.end());
    }
  }
  return search;
}

// A node at one end of the mesh (George & Liu's pseudo-peripheral node): search from a node,
// move to the least connected node of its last level, and again while the number of levels
// grows. `visited` marks the nodes numbered already (other components), which stay out.
int pseudo_peripheral(const std::vector<std::vector<int>>& adjacency, int start,
                      const std::vector<char>& visited) {
  int levels = 0;
  std::vector<int> order;
  for (int attempt = 0; attempt < 8; ++attempt) {
    std::vector<char> seen = visited;
    order.clear();
    const Search search = breadth_first(adjacency, start, seen, order);
    if (search.levels <= levels) break;
    levels = search.levels;
    start = *std::min_element(
        order.begin() + static_cast<long>(search.last_level), order.end(), [&](int a, int b) {
          return std::make_pair(degree(adjacency, a), a) < std::make_pair(degree(adjacency, b), b);
        });
  }
  return start;
}

}  // namespace

std::vector<int> reverse_cuthill_mckee(const std::vector<std::vector<int>>& adjacency) {
  const int n = static_cast<int>(adjacency.size());
  std::vector<char> visited(adjacency.size(), 0);
  std::vector<int> order;
  order.reserve(adjacency.size());
  for (int i = 0; i < n; ++i) {  // one search per connected component
    if (visited[i]) continue;
    breadth_first(adjacency, pseudo_peripheral(adjacency, i, visited), visited, order);
  }
  std::reverse(order.begin(), order.end());  // George 1971: a smaller profile, the same bandwidth
  return order;
}

namespace {

// The bits of v (21 of them) spread to every third bit: the x, y and z bits of a Morton key
// interleave.
std::uint64_t spread_bits(std::uint64_t v) {
  v &= 0x1fffff;
  v = (v | v << 32) & 0x1f00000000ffffULL;
  v = (v | v << 16) & 0x1f0000ff0000ffULL;
  v = (v | v << 8) & 0x100f00f00f00f00fULL;
  v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
  v = (v | v << 2) & 0x1249249249249249ULL;
  return v;
}

}  // namespace

std::vector<int> morton_order(const Eigen::Matrix3Xd& X) {
  const Eigen::Vector3d low = X.rowwise().minCoeff(), high = X.rowwise().maxCoeff();
  // One scale for the three axes: a cell of the curve is a cube, also on a thin plate.
  const double extent = std::max((high - low).maxCoeff(), 1e-300);
  const double cells = static_cast<double>((1 << 21) - 1);
  std::vector<std::uint64_t> key(static_cast<std::size_t>(X.cols()));
  for (Eigen::Index i = 0; i < X.cols(); ++i) {
    std::uint64_t k = 0;
    for (int a = 0; a < 3; ++a)
      k |= spread_bits(static_cast<std::uint64_t>((X(a, i) - low[a]) / extent * cells)) << a;
    key[static_cast<std::size_t>(i)] = k;
  }
  std::vector<int> order(key.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return key[a] < key[b]; });
  return order;
}

NodeOrder node_order(const TetMesh& mesh, Ordering ordering) {
  std::vector<int> old_of_new(static_cast<std::size_t>(mesh.num_nodes()));
  std::iota(old_of_new.begin(), old_of_new.end(), 0);
  if (ordering == Ordering::rcm) old_of_new = reverse_cuthill_mckee(node_adjacency(mesh));
  if (ordering == Ordering::morton) old_of_new = morton_order(mesh.X);
  return order_from(std::move(old_of_new));
}

namespace {

TetMesh renumbered_mesh(const TetMesh& mesh, const NodeOrder& order, bool sort_elements) {
  TetMesh out = mesh;
  for (int k = 0; k < mesh.num_nodes(); ++k) out.X.col(k) = mesh.X.col(order.old_of_new[k]);
  for (auto& t : out.tets)
    for (int a = 0; a < 4; ++a) t[a] = order.new_of_old[t[a]];
  for (auto& f : out.boundary)
    for (int a = 0; a < 3; ++a) f[a] = order.new_of_old[f[a]];
  if (!sort_elements) return out;
  // Elements by their smallest node, then the next: the pass walks the nodes forwards.
  std::stable_sort(
      out.tets.begin(), out.tets.end(), [](const Eigen::Vector4i& a, const Eigen::Vector4i& b) {
        std::array<int, 4> ka = {a[0], a[1], a[2], a[3]}, kb = {b[0], b[1], b[2], b[3]};
        std::sort(ka.begin(), ka.end());
        std::sort(kb.begin(), kb.end());
        return ka < kb;
      });
  return out;
}

}  // namespace

Scene renumbered(const Scene& scene, const NodeOrder& order, bool sort_elements) {
  if (order.old_of_new.size() != static_cast<std::size_t>(scene.mesh.num_nodes()))
    throw std::invalid_argument("node order: not an order of this mesh's nodes");
  if (order.identity() && !sort_elements) return scene;
  Scene out = scene;
  out.mesh = renumbered_mesh(scene.mesh, order, sort_elements);
  for (auto& c : out.constraints) c.node = order.new_of_old[c.node];
  std::stable_sort(
      out.constraints.begin(), out.constraints.end(),
      [](const NodeConstraint& a, const NodeConstraint& b) { return a.node < b.node; });
  for (auto& f : out.external_forces) f.node = order.new_of_old[f.node];
  return out;
}

OrderQuality order_quality(const TetMesh& mesh) {
  OrderQuality q;
  const auto adjacency = node_adjacency(mesh);
  for (std::size_t i = 0; i < adjacency.size(); ++i) {
    const int low = adjacency[i].front(), high = adjacency[i].back();  // sorted rows
    q.bandwidth = std::max<long long>(
        q.bandwidth, std::max(static_cast<int>(i) - low, high - static_cast<int>(i)));
    q.profile += static_cast<double>(static_cast<int>(i) - low);
  }
  for (const auto& t : mesh.tets) q.element_spread += t.maxCoeff() - t.minCoeff();
  q.element_spread /= std::max(1, mesh.num_tets());
  return q;
}

}  // namespace fem::ch11
