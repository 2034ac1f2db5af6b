// Chapter 10's parts (see parts.hpp): the V-cycle as the PCG's preconditioner, and the guess.
#include "chapters/10_multigrid/parts.hpp"

#include <algorithm>
#include <stdexcept>

namespace fem::ch10 {

namespace {

Eigen::VectorXd rest_positions(const Scene& scene) {
  return Eigen::Map<const Eigen::VectorXd>(scene.mesh.X.data(),
                                           static_cast<Eigen::Index>(scene.mesh.X.size()));
}

// The hierarchy's settings, checked before the hierarchy is built.
const MultigridSettings& checked(const MultigridSettings& settings) {
  check(settings);
  return settings;
}

void check_extrapolation(int order) {
  if (order < 0 || order > 2)
    throw std::invalid_argument("multigrid stepper: the guess's extrapolation order is 0, 1 or 2");
}

}  // namespace

void check(const MultigridStepperSettings& settings) {
  check(settings.multigrid);
  check_extrapolation(settings.extrapolation);
}

void MultigridPreconditioner::prepare(const ch07::BlockSparseMatrix& A) {
  // Every thread of the solve's team: the multigrid shares out its own row blocks.
  multigrid_.factorize(A.blocks);
}

void MultigridPreconditioner::apply(const Eigen::VectorXd& r, Eigen::VectorXd& s) {
  // One V-cycle, on every thread of the team, ending with a barrier: the PCG then reads s on
  // any row. Filtered on both sides by the PCG, S M S is symmetric positive definite on the
  // free subspace, as PCG needs.
  multigrid_.apply(r, s);
}

MultigridPreconditioner::MultigridPreconditioner(const ch08::PartSetup& setup, const Params& params)
    : multigrid_(checked(params)) {
  multigrid_.analyze_pattern(setup.system.A.row_start, setup.system.A.column,
                             rest_positions(setup.scene), setup.scene.constraints);
}

namespace {

// One level's line of the summary: its block rows, stored blocks and their bytes in double.
template <class Level>
void describe_level(std::ostream& out, int l, const Level& level) {
  const int block = Level::block_size;
  const long long blocks = static_cast<long long>(level.A.column.size());
  out << "    level " << l << ": " << level.nodes() << " block rows of " << block << "x" << block
      << ", " << blocks << " blocks, " << blocks * block * block * sizeof(double) / 1024
      << " KiB of blocks in double\n";
}

}  // namespace

void MultigridPreconditioner::describe(std::ostream& out) const {
  out << "  multigrid: " << multigrid_.levels() << " levels\n";
  describe_level(out, 0, multigrid_.fine_level());
  for (std::size_t l = 0; l < multigrid_.coarse_levels().size(); ++l)
    describe_level(out, static_cast<int>(l) + 1, multigrid_.coarse_levels()[l]);
}

Extrapolation::Extrapolation(const ch08::PartSetup& setup, const Params& params)
    : order_(params.order) {
  check_extrapolation(order_);
  for (auto& h : history_) h = Eigen::VectorXd::Zero(setup.model.dofs);
}

void Extrapolation::guess(Eigen::VectorXd& y) {
  // y holds the last solution y_n; history_ the two before it. The velocity change of a smooth
  // motion changes smoothly, so the guess starts closer. Element by element on one thread: a
  // few multiply-adds per unknown, no sum, the same bits for any thread count.
  static constexpr double kWeights[3][3] = {{1.0, 0.0, 0.0}, {2.0, -1.0, 0.0}, {3.0, -3.0, 1.0}};
  const int order = std::min(order_, solves_ - 1);  // only past solutions count
  for (Eigen::Index k = 0; k < y.size(); ++k) {
    const double last = y[k];
    if (order > 0) {
      double guess = kWeights[order][0] * last;
      for (int j = 1; j <= order; ++j) guess += kWeights[order][j] * history_[j - 1][k];
      y[k] = guess;
    }
    history_[1][k] = history_[0][k];
    history_[0][k] = last;
  }
  ++solves_;
}

}  // namespace fem::ch10
