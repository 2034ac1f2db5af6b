#include "chapters/10_multigrid/work.hpp"

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

// Restriction by R = P^T (stored apart) and prolongation by P, each read once, with the
// residual read and x read and written back (the coarse vectors are a level's smaller ones).
PhaseWork level_transfer(const LevelSize& l, int scalar) {
  const double operator_bytes =
      double(l.transfer) * l.block * kModes * scalar + double(l.transfer + l.nodes + 1) * 4;
  const double vector = double(l.nodes) * l.block * scalar;
  PhaseWork w;
  w.bytes_read = 2 * operator_bytes + 2 * vector;
  w.bytes_written = vector;
  w.flops_double = 2 * 2 * double(l.transfer) * l.block * kModes;
  w.working_set = 2 * operator_bytes;
  return w;
}

void add(PhaseWork& to, const PhaseWork& w, double times) {
  to.bytes_read += times * w.bytes_read;
  to.bytes_written += times * w.bytes_written;
  to.bytes_allocated += times * w.bytes_allocated;
  to.flops_double += times * w.flops_double;
  to.working_set += w.working_set;
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
  for (const LevelSize& l : levels) {
    if (l.coarsest) {
      // The dense Cholesky factor (double), read by two triangular solves.
      const double n = double(l.nodes) * l.block;
      w.bytes_read += n * n * sizeof(double);
      w.working_set += n * n * sizeof(double);
      w.flops_double += 2 * n * n;
      continue;
    }
    add(w, level_product(l, scalar), products);
    add(w, level_transfer(l, scalar), 1.0);
  }
  if (float_arithmetic) {
    // The levels' arithmetic is in float; the coarsest factor's stays double.
    const LevelSize& last = levels.back();
    const double n = last.coarsest ? double(last.nodes) * last.block : 0.0;
    w.flops_float = w.flops_double - 2 * n * n;
    w.flops_double = 2 * n * n;
  }
  return w;
}

std::vector<PhaseWork> multigrid_work(const MultigridStepper& stepper, const Scene& scene,
                                      const WorkCounts& counts, int scalar, bool float_arithmetic) {
  const Multigrid& mg = stepper.multigrid();
  const PhaseWork v_cycle =
      v_cycle_work(multigrid_levels(mg), smoother_products(mg), scalar, float_arithmetic);
  // Per solve: the fine level's inverse diagonal from A's diagonal blocks; in float, every
  // fine block read in double and written in float too.
  const double nodes = scene.mesh.num_nodes();
  double read = nodes * kBlock, written = nodes * 9.0 * scalar;
  if (scalar < 8) {
    read += double(stepper.system_matrix().blocks.size()) * kBlock;
    written += double(stepper.system_matrix().blocks.size()) * 9.0 * scalar;
  }
  return ch08::fused_work(stepper, scene, counts, v_cycle, read, written);
}

std::vector<PhaseWork> count_work(const MultigridStepper& stepper, const Scene& scene,
                                  const WorkCounts& counts) {
  return multigrid_work(stepper, scene, counts, 8, false);
}

}  // namespace fem::ch10
