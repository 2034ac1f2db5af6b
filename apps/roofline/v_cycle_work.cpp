// One V-cycle's work, and the one function that reads chapter 10's hierarchy for it
// (multigrid_levels, smoother_products: where a change of chapter 10's API is ported).
#include <algorithm>

#include "apps/roofline/work.hpp"
#include "chapters/10_multigrid/multigrid.hpp"
#include "chapters/10_multigrid/report.hpp"

namespace fem::roofline {

std::vector<LevelSize> multigrid_levels(const ch10::Multigrid& multigrid) {
  std::vector<LevelSize> levels;
  for (int l = 0; l < multigrid.levels(); ++l) {
    LevelSize level;
    level.block = l == 0 ? 3 : ch10::kModes;
    level.nodes = ch10::level_dofs(multigrid, l) / level.block;
    level.blocks = ch10::level_blocks(multigrid, l);
    level.coarsest = l + 1 == multigrid.levels();
    level.transfer = level.coarsest ? 0 : ch10::prolongator_blocks(multigrid, l);
    levels.push_back(level);
  }
  return levels;
}

int smoother_products(const ch10::Multigrid& multigrid) {
  using ch10::Smoother;
  const ch10::SmootherSettings& s = multigrid.settings().relax;
  // A polynomial smoother from zero skips the product of its first step; the residual adds
  // one: pre (steps - 1) + residual (1) + post (steps) products (ch10::v_cycle, smooth).
  if (s.smoother == Smoother::Chebyshev) return 2 * s.chebyshev_degree * s.sweeps;
  if (s.smoother == Smoother::Jacobi) return 2 * s.sweeps;
  // Gauss-Seidel: a sweep reads the matrix once; after a single forward sweep the residual
  // comes with it (ch10::residual).
  return 2 * s.sweeps + (s.sweeps == 1 ? 0 : 1);
}

namespace {

// One smoother product on a level of B x B blocks: the blocks and their indices, the inverse
// diagonal, and the vectors it streams (its input, b, the direction read and written, its
// output); per block 2 B^2 flops, per row the inverse diagonal's 2 B^2 and the update's.
PhaseWork level_product(const LevelSize& l, int scalar) {
  const double b2 = double(l.block) * l.block, dofs = double(l.nodes) * l.block;
  const double matrix = double(l.blocks) * b2 * scalar + double(l.blocks + l.nodes + 1) * 4;
  const double inverse = double(l.nodes) * b2 * scalar;
  const double vectors = 5 * dofs * scalar;
  return {"", matrix + inverse + vectors, 2 * b2 * double(l.blocks + l.nodes) + 6 * dofs, 0.0,
          matrix + inverse + vectors};
}

// Restriction by R = P^T (stored apart) and prolongation by P: each read once, with the
// residual, the coarse right-hand side, the coarse solution and x + P x_c.
PhaseWork level_transfer(const LevelSize& l, int scalar) {
  const double operator_bytes =
      double(l.transfer) * l.block * ch10::kModes * scalar + double(l.transfer + l.nodes + 1) * 4;
  const double vectors = 3 * double(l.nodes) * l.block * scalar;
  return {"", 2 * operator_bytes + vectors, 2 * 2 * double(l.transfer) * l.block * ch10::kModes,
          0.0, 2 * operator_bytes};
}

}  // namespace

PhaseWork v_cycle_work(const std::vector<LevelSize>& levels, int products, int scalar,
                       bool float_arithmetic) {
  PhaseWork w{"v-cycle", 0.0, 0.0, 0.0, 0.0};
  double flops = 0.0;
  for (const LevelSize& l : levels) {
    if (l.coarsest) {
      // The dense Cholesky factor (double in both chapters), read by two triangular solves.
      const double n = double(l.nodes) * l.block;
      w.bytes += n * n * sizeof(double);
      w.working_set += n * n * sizeof(double);
      w.flops_double += 2 * n * n;
      continue;
    }
    const PhaseWork product = level_product(l, scalar), transfer = level_transfer(l, scalar);
    w.bytes += products * product.bytes + transfer.bytes;
    w.working_set += product.working_set + transfer.working_set;
    flops += products * product.flops_double + transfer.flops_double;
  }
  (float_arithmetic ? w.flops_float : w.flops_double) += flops;
  return w;
}

}  // namespace fem::roofline
