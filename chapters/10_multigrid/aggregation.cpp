// Chapter 10: aggregation (see aggregation.hpp).
#include "chapters/10_multigrid/aggregation.hpp"

#include <algorithm>

namespace fem::ch10 {

void sort_unique(std::vector<int>& v) {
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
}

// Standard aggregation with every connection of the graph strong: PyAMG's default strength
// for smoothed aggregation is symmetric with theta = 0, which keeps all of them. So
// aggregates depend on the mesh alone and are built once.
std::vector<int> aggregate_nodes(const Rows& graph, int& count) {
  const int n = static_cast<int>(graph.size());
  std::vector<int> aggregate(n, -1);
  count = 0;
  // 1: a node whose neighbours are all unaggregated seeds an aggregate with them.
  for (int i = 0; i < n; ++i) {
    if (aggregate[i] != -1) continue;
    const bool free =
        std::all_of(graph[i].begin(), graph[i].end(), [&](int j) { return aggregate[j] == -1; });
    if (!free) continue;
    for (const int j : graph[i]) aggregate[j] = count;
    aggregate[i] = count++;
  }
  // 2: the rest join a neighbouring aggregate of step 1.
  const std::vector<int> seeded = aggregate;
  for (int i = 0; i < n; ++i) {
    if (aggregate[i] != -1) continue;
    for (const int j : graph[i])
      if (seeded[j] != -1) {
        aggregate[i] = seeded[j];
        break;
      }
  }
  // 3: whatever is left (no aggregated neighbour) forms aggregates of its own.
  for (int i = 0; i < n; ++i) {
    if (aggregate[i] != -1) continue;
    for (const int j : graph[i])
      if (aggregate[j] == -1) aggregate[j] = count;
    aggregate[i] = count++;
  }
  return aggregate;
}

// This graph, not the pattern of P^T A P (which also links aggregates two and three nodes
// apart), is what the next level aggregates: on the wider pattern the aggregates grow so large
// that the level below holds too few of them to represent the one above (`fem_lessons
// multigrid` prints every level's size).
Rows aggregate_graph(const Rows& graph, const std::vector<int>& aggregate, int count) {
  Rows coarse(count);
  for (std::size_t i = 0; i < graph.size(); ++i)
    for (const int j : graph[i]) coarse[aggregate[i]].push_back(aggregate[j]);
  for (auto& row : coarse) sort_unique(row);
  return coarse;
}

}  // namespace fem::ch10
