// This chapter's work per phase (chapters/work.hpp: the model): the fused pass's phases as
// before, and a solve whose preconditioner is one V-cycle per iteration over every level of
// the hierarchy, each level's kernels a part of the solve at their own working set; the counts of
// one V-cycle for the chapters that keep it.
#pragma once

#include <vector>

#include "chapters/10_multigrid/multigrid.hpp"
#include "chapters/10_multigrid/stepper.hpp"
#include "chapters/work.hpp"

namespace fem::ch10 {

std::vector<PhaseWork> count_work(const MultigridStepper& stepper, const Scene& scene,
                                  const WorkCounts& counts);

// The V-cycle chapters' phases, the levels' numbers and vectors at `scalar` bytes (8: double,
// 4: float), the V-cycle's flops in float arithmetic or in double.
std::vector<PhaseWork> multigrid_work(const MultigridStepper& stepper, const Scene& scene,
                                      const WorkCounts& counts, int scalar, bool float_arithmetic);

// One level of the hierarchy as the counts need it.
struct LevelSize {
  int block = 3;           // 3 on the mesh, kModes on the aggregates
  long long nodes = 0;     // block rows
  long long blocks = 0;    // stored blocks of the level's matrix
  long long transfer = 0;  // blocks of P to the next level (0 on the coarsest)
  bool coarsest = false;   // solved by a dense Cholesky factor
};
std::vector<LevelSize> multigrid_levels(const Multigrid& multigrid);
// Matrix products per level per V-cycle: pre- and post-smoothing and the residual.
int smoother_products(const Multigrid& multigrid);

// One V-cycle's bytes and flops over `levels`, as parts per level: the smoothing steps and
// the residual (`products` products), the restriction, the prolongation, the coarsest solve;
// each part's working set that level's data alone.
PhaseWork v_cycle_work(const std::vector<LevelSize>& levels, int products, int scalar,
                       bool float_arithmetic);

}  // namespace fem::ch10
