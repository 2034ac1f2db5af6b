// Chapter 10: reports on a hierarchy (see report.hpp).
#include "chapters/10_multigrid/report.hpp"

namespace fem::ch10 {

namespace {

// f(level) on level 0 (3x3 blocks) or a coarse level (6x6 blocks).
template <class F>
auto on_level(const Multigrid& mg, int level, F&& f) {
  return level == 0 ? f(mg.fine_level()) : f(mg.coarse_levels().at(level - 1));
}

}  // namespace

int level_dofs(const Multigrid& mg, int level) {
  return on_level(mg, level, [](const auto& l) { return l.dofs(); });
}

long long level_blocks(const Multigrid& mg, int level) {
  return on_level(mg, level,
                  [](const auto& l) { return static_cast<long long>(l.A.column.size()); });
}

long long prolongator_blocks(const Multigrid& mg, int level) {
  return on_level(mg, level,
                  [](const auto& l) { return static_cast<long long>(l.transfer.P.column.size()); });
}

int level_row_blocks(const Multigrid& mg, int level) {
  return on_level(mg, level, [](const auto& l) { return l.rows.count(); });
}

Eigen::SparseMatrix<double> level_matrix(const Multigrid& mg, int level) {
  return on_level(mg, level, [](const auto& l) { return l.A.to_sparse(l.values, l.dofs()); });
}

Eigen::SparseMatrix<double> prolongator(const Multigrid& mg, int level) {
  const int coarse_dofs = level_dofs(mg, level + 1);
  return on_level(mg, level, [&](const auto& l) { return l.transfer.P.to_sparse(coarse_dofs); });
}

Eigen::VectorXd missing_modes(const Multigrid& mg, int level) {
  const auto& l = mg.coarse_levels().at(level - 1);
  Eigen::VectorXd u(l.dofs());
  for (int c = 0; c < l.nodes(); ++c) u.segment<kModes>(kModes * c) = l.missing_modes[c];
  return u;
}

}  // namespace fem::ch10
