// Chapter 10: the set-up data of the hierarchy, per level: the graph its aggregation reads, the
// aggregates, the near-null-space modes and the tentative prolongator T built from them. The
// V-cycle reads none of it. The hierarchy keeps it until it has smoothed P on the first matrix
// (the modes are improved on that matrix first), then drops it, as AMGCL drops its coarsening
// object after set-up; only a prolongator smoothed at every refresh keeps T.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "chapters/10_multigrid/aggregation.hpp"
#include "chapters/10_multigrid/level.hpp"

namespace fem::ch10 {

template <int B>
struct Aggregates {
  Rows graph;                                               // the neighbours aggregation considers
  std::vector<int> aggregate;                               // per node: its aggregate (coarse node)
  std::vector<Eigen::Matrix<double, B, kModes>> modes;      // per node: its near-null space
  std::vector<Eigen::Matrix<double, B, kModes>> tentative;  // per node: its block of T
};

// The finest level's aggregates, and those of every coarse level.
struct Coarsening {
  Aggregates<3> fine;
  std::vector<Aggregates<kModes>> coarse;
};

}  // namespace fem::ch10
