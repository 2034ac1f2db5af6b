// Chapter 10: aggregation, the first stage of smoothed aggregation: the nodes grouped into
// aggregates, each of which becomes one coarse node (Vanek, Mandel & Brezina 1996; PyAMG's
// standard_aggregation). On the mesh's graph at set-up, and again on each level's graph of
// aggregates.
#pragma once

#include <vector>

namespace fem::ch10 {

using Rows = std::vector<std::vector<int>>;  // a pattern under construction: columns per row

// The entries of v sorted, each once.
void sort_unique(std::vector<int>& v);

// Per node, its aggregate; count receives the number of aggregates. graph[i] lists i's
// neighbours (i included).
std::vector<int> aggregate_nodes(const Rows& graph, int& count);

// The graph of the aggregates: two are neighbours when two of their nodes are.
Rows aggregate_graph(const Rows& graph, const std::vector<int>& aggregate, int count);

}  // namespace fem::ch10
