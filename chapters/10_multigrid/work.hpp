// This chapter's preconditioner's work (chapters/08_element_kernels/work.hpp: counted part by
// part): one V-cycle per iteration over every level of the hierarchy, each level's kernels a
// part of the solve at their own working set; the counts of one V-cycle for the chapters that
// keep it.
#pragma once

#include <vector>

#include "chapters/08_element_kernels/work.hpp"
#include "chapters/10_multigrid/multigrid.hpp"
#include "chapters/10_multigrid/parts.hpp"
#include "chapters/work.hpp"

namespace fem::ch10 {

ch08::PreconditionerWork preconditioner_work(const MultigridPreconditioner& part,
                                             const ch08::WorkInput& in);
// The V-cycle alone is not timed in double (chapter 12 times its float smoothing step).
inline std::vector<PartKernel> preconditioner_kernels(MultigridPreconditioner&,
                                                      const ch08::KernelInput&) {
  return {};
}
// A V-cycle of `multigrid` applied once, its levels' numbers and vectors at `scalar` bytes (8:
// double, 4: float), its flops in float arithmetic or in double, and its set-up per solve.
ch08::PreconditionerWork multigrid_work(const Multigrid& multigrid, const ch08::WorkInput& in,
                                        int scalar, bool float_arithmetic);

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
