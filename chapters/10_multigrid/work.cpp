#include "chapters/10_multigrid/work.hpp"

#include <string>
#include <utility>

#include "chapters/08_element_kernels/work.hpp"
#include "chapters/10_multigrid/report.hpp"

namespace fem::ch10 {

namespace {

constexpr double kBlock = 9 * sizeof(double);  // a 3x3 block of doubles

// One smoother product on a level of B x B blocks: the blocks and their indices, the inverse
// diagonal, its input, b and the direction read; the direction written back and the output
// written fresh. Per block 2 B^2 flops, per row the inverse diagonal's 2 B^2 and the update's.
PhaseWork level_product(const LevelSize& l, int scalar) {
  const double b2 = double(l.block) * l.block, vector = double(l.nodes) * l.block * scalar;
  const double matrix = double(l.blocks) * b2 * scalar + double(l.blocks + l.nodes + 1) * 4;
  const double inverse = double(l.nodes) * b2 * scalar;
  PhaseWork w;
  w.bytes_read = matrix + inverse + 3 * vector;
  w.bytes_written = 2 * vector;
  w.bytes_allocated = vector;
  w.flops_double = 2 * b2 * double(l.blocks + l.nodes) + 6 * double(l.nodes) * l.block;
  w.working_set = matrix + inverse + 4 * vector;
  return w;
}

// Restriction by R = P^T (stored apart) with the residual read, or prolongation by P with x
// read and written back: the operator and one of the level's vectors each (the coarse
// vectors are the next level's, smaller ones).
PhaseWork level_transfer(const LevelSize& l, int scalar, bool prolongation) {
  const double operator_bytes =
      double(l.transfer) * l.block * kModes * scalar + double(l.transfer + l.nodes + 1) * 4;
  const double vector = double(l.nodes) * l.block * scalar;
  PhaseWork w;
  w.bytes_read = operator_bytes + vector;
  w.bytes_written = prolongation ? vector : 0.0;
  w.flops_double = 2 * double(l.transfer) * l.block * kModes;
  w.working_set = operator_bytes + vector;
  return w;
}

// The part named for its level, its arithmetic in float where the levels' is.
PhaseWork level_part(PhaseWork w, const std::string& name, bool float_arithmetic) {
  w.phase = name;
  if (float_arithmetic) std::swap(w.flops_float, w.flops_double);
  return w;
}

}  // namespace

std::vector<LevelSize> multigrid_levels(const Multigrid& multigrid) {
  std::vector<LevelSize> levels;
  for (int l = 0; l < multigrid.levels(); ++l) {
    LevelSize level;
    level.block = l == 0 ? 3 : kModes;
    level.nodes = level_dofs(multigrid, l) / level.block;
    level.blocks = level_blocks(multigrid, l);
    level.coarsest = l + 1 == multigrid.levels();
    level.transfer = level.coarsest ? 0 : prolongator_blocks(multigrid, l);
    levels.push_back(level);
  }
  return levels;
}

int smoother_products(const Multigrid& multigrid) {
  const SmootherSettings& s = multigrid.settings().relax;
  // A polynomial smoother from zero skips the product of its first step; the residual adds
  // one: pre (steps - 1) + residual (1) + post (steps) products (v_cycle, smooth).
  if (s.smoother == Smoother::Chebyshev) return 2 * s.chebyshev_degree * s.sweeps;
  if (s.smoother == Smoother::Jacobi) return 2 * s.sweeps;
  // Gauss-Seidel: a sweep reads the matrix once; after a single forward sweep the residual
  // comes with it (residual).
  return 2 * s.sweeps + (s.sweeps == 1 ? 0 : 1);
}

PhaseWork v_cycle_work(const std::vector<LevelSize>& levels, int products, int scalar,
                       bool float_arithmetic) {
  PhaseWork w;
  w.phase = "v-cycle";
  for (std::size_t k = 0; k < levels.size(); ++k) {
    const LevelSize& l = levels[k];
    const std::string level = "level " + std::to_string(k) + " ";
    if (l.coarsest) {
      // The dense Cholesky factor (double, also in a float V-cycle), read by two triangular
      // solves.
      const double n = double(l.nodes) * l.block;
      PhaseWork coarsest;
      coarsest.phase = level + "coarsest solve";
      coarsest.bytes_read = n * n * sizeof(double);
      coarsest.flops_double = 2 * n * n;
      coarsest.working_set = n * n * sizeof(double);
      w.add_part(coarsest, 1.0);
      w.working_set += coarsest.working_set;
      continue;
    }
    const PhaseWork product = level_product(l, scalar);
    w.add_part(level_part(product, level + "smoothing and residual", float_arithmetic), products);
    w.add_part(
        level_part(level_transfer(l, scalar, false), level + "restriction", float_arithmetic), 1.0);
    w.add_part(
        level_part(level_transfer(l, scalar, true), level + "prolongation", float_arithmetic), 1.0);
    w.working_set += product.working_set + level_transfer(l, scalar, true).working_set;
  }
  return w;
}

ch08::PreconditionerWork multigrid_work(const Multigrid& mg, const ch08::WorkInput& in, int scalar,
                                        bool float_arithmetic) {
  const PhaseWork v_cycle =
      v_cycle_work(multigrid_levels(mg), smoother_products(mg), scalar, float_arithmetic);
  // Per solve: the fine level's inverse diagonal from A's diagonal blocks; in float, every
  // fine block read in double and written in float too.
  const double nodes = in.scene.mesh.num_nodes();
  double read = nodes * kBlock, written = nodes * 9.0 * scalar;
  if (scalar < 8) {
    read += double(in.A.blocks.size()) * kBlock;
    written += double(in.A.blocks.size()) * 9.0 * scalar;
  }
  return {v_cycle, read, written};
}

ch08::PreconditionerWork preconditioner_work(const MultigridPreconditioner& part,
                                             const ch08::WorkInput& in) {
  return multigrid_work(part.multigrid(), in, 8, false);
}

}  // namespace fem::ch10
