// Chapter 10: the hierarchy that wires the stages. analyze_pattern: aggregates, the tentative
// prolongator T from the rigid-body modes, the fixed patterns with their index tables and
// every level's fixed row blocks. factorize, every step: the finest level's smoother; at a
// refresh also P = (I - w D^-1 A) T (the first time, after the modes are improved on the
// first matrix), A_c = P^T A P, the coarse smoothers and the coarsest Cholesky, numbers only.
// apply, every PCG iteration: one V-cycle. factorize and apply run on the whole team: every
// loop a StaticShare (chapter 09's `omp for` written out) over fixed row blocks, each row
// written by one thread, every sum in a fixed order.
#include "chapters/10_multigrid/multigrid.hpp"

#include <algorithm>
#include <random>
#include <stdexcept>

#include "chapters/09_threads/parallel.hpp"
#include "chapters/10_multigrid/aggregation.hpp"
#include "chapters/10_multigrid/coarsening.hpp"
#include "chapters/10_multigrid/galerkin.hpp"
#include "chapters/10_multigrid/near_null_space.hpp"
#include "chapters/10_multigrid/prolongator.hpp"
#include "chapters/10_multigrid/v_cycle.hpp"

namespace fem::ch10 {

namespace {

// A level's tables and vectors, and the smoother it runs.
template <int B>
void set_up(Level<B>& level, const MultigridSettings& settings) {
  set_up_level(level, settings.rows);
  level.smoother.gauss_seidel = settings.relax.smoother == Smoother::GaussSeidel;
  level.smoother.sweeps = settings.relax.sweeps;
}

// The transfer from `fine` to a new level `coarse`: all patterns and tables, and the graph
// that the coarse level aggregates.
template <int B>
void build_transfer(Level<B>& fine, const Aggregates<B>& aggregates, int count,
                    const MultigridSettings& settings, Level<kModes>& coarse,
                    Aggregates<kModes>& coarse_aggregates) {
  fine.coarsest = false;
  coarse_aggregates.graph = aggregate_graph(aggregates.graph, aggregates.aggregate, count);
  build_prolongator_pattern(fine, aggregates.aggregate, count,
                            settings.coarsening.smooth_prolongator);
  build_ap_pattern(fine);
  build_galerkin_tables(fine, count, coarse);
  set_up(coarse, settings);
  coarse_aggregates.modes.resize(count);
}

const Aggregates<3>& aggregates_of(const Coarsening& c, const Level<3>&, std::size_t) {
  return c.fine;
}
const Aggregates<kModes>& aggregates_of(const Coarsening& c, const Level<kModes>&,
                                        std::size_t next) {
  return c.coarse[next - 1];
}

}  // namespace

void check(const MultigridSettings& s) {
  const CoarseningSettings& c = s.coarsening;
  const SmootherSettings& r = s.relax;
  if (c.modes != 3 && c.modes != kModes)
    throw std::invalid_argument("multigrid: modes must be 3 or 6");
  if (r.sweeps < 1 || s.max_levels < 1 || c.power_iterations < 1 || s.refresh.every < 1 ||
      s.rows.max_blocks < 1 || s.rows.block_rows < 1 || r.chebyshev_degree < 1)
    throw std::invalid_argument(
        "multigrid: sweeps, levels, power iterations, the coarse refresh's period, blocks, block "
        "rows and the Chebyshev degree must be at least 1");
  if (c.improve_candidates < 0 || s.rows.serial_rows < 0)
    throw std::invalid_argument("multigrid: candidate sweeps and serial rows must be 0 or more");
  // The coarsest level is at least one aggregate's modes.
  if (s.max_coarse_dofs < kModes)
    throw std::invalid_argument("multigrid: the coarsest size (max coarse dofs) must be at least " +
                                std::to_string(kModes));
  if (!(r.chebyshev_ratio > 1.0) || !(s.refresh.growth >= 0.0) || !(r.jacobi_weight >= 0.0))
    throw std::invalid_argument(
        "multigrid: the Chebyshev ratio must exceed 1, growth and Jacobi weight be >= 0");
}

Multigrid::Multigrid(const MultigridSettings& settings)
    : settings_(settings), refresh_rule_(settings.refresh) {
  check(settings_);
}

Multigrid::~Multigrid() = default;

// ---- set-up: the pattern, once --------------------------------------------------------------

void Multigrid::analyze_pattern(const std::vector<int>& row_start, const std::vector<int>& column,
                                const Eigen::VectorXd& rest_positions,
                                const std::vector<NodeConstraint>& constraints) {
  fine_.A.row_start = row_start;
  fine_.A.column = column;
  if (rest_positions.size() != 3 * fine_.nodes())
    throw std::invalid_argument("multigrid: rest positions do not match the pattern");
  set_up(fine_, settings_);
  rest_positions_ = rest_positions;
  modes_constraints_ = constraints;
  coarsening_ = std::make_unique<Coarsening>();
  Aggregates<3>& fine = coarsening_->fine;

  std::mt19937 random(2015);  // the power iterations' start vectors: fixed, so deterministic
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  const auto start_vector = [&](Eigen::VectorXd& start, Eigen::Index size) {
    start.resize(size);
    for (Eigen::Index k = 0; k < size; ++k) start[k] = uniform(random);
  };
  start_vector(fine_.smoother.power_start, fine_.dofs());

  coarse_.reserve(settings_.max_levels);  // no reallocation: levels refer to their neighbours
  int count = 0;
  const auto worth_coarsening = [&](int dofs, int nodes, int aggregates) {
    return dofs > settings_.max_coarse_dofs && levels() < settings_.max_levels &&
           aggregates < nodes;
  };
  fine.graph.resize(fine_.nodes());
  for (int i = 0; i < fine_.nodes(); ++i)
    fine.graph[i].assign(column.begin() + row_start[i], column.begin() + row_start[i + 1]);
  fine.aggregate = aggregate_nodes(fine.graph, count);
  if (!worth_coarsening(fine_.dofs(), fine_.nodes(), count)) {
    finish_coarsest(fine_);
    return;
  }
  fine.modes = rigid_body_modes(rest_positions, constraints, fine.aggregate, count,
                                settings_.coarsening.modes);
  std::vector<Aggregates<kModes>>& coarse = coarsening_->coarse;
  coarse.reserve(settings_.max_levels);
  coarse_.emplace_back();
  coarse.emplace_back();
  build_transfer(fine_, fine, count, settings_, coarse_.back(), coarse.back());
  while (true) {
    start_vector(coarse_.back().smoother.power_start, coarse_.back().dofs());
    coarse.back().aggregate = aggregate_nodes(coarse.back().graph, count);
    if (!worth_coarsening(coarse_.back().dofs(), coarse_.back().nodes(), count)) break;
    coarse_.emplace_back();
    coarse.emplace_back();
    const std::size_t l = coarse_.size() - 2;
    build_transfer(coarse_[l], coarse[l], count, settings_, coarse_.back(), coarse.back());
  }
  finish_coarsest(coarse_.back());
  build_tentatives();
}

// T of every level from its modes, the next level's modes from T, and P = T until smoothed.
void Multigrid::build_tentatives() {
  const auto build = [](auto& level, auto& aggregates, Level<kModes>& coarse,
                        Aggregates<kModes>& coarse_aggregates) {
    tentative_prolongator(aggregates.modes, aggregates.aggregate, coarse.nodes(),
                          aggregates.tentative, coarse_aggregates.modes, coarse.missing_modes);
    set_tentative(level, aggregates.tentative);
  };
  if (coarse_.empty()) return;
  Coarsening& c = *coarsening_;
  build(fine_, c.fine, coarse_[0], c.coarse[0]);
  for (std::size_t l = 0; l + 1 < coarse_.size(); ++l)
    build(coarse_[l], c.coarse[l], coarse_[l + 1], c.coarse[l + 1]);
}

// Once P is smoothed, the set-up data goes but for what set_constraints needs to build it again
// (each level's aggregates: the modes come from the rest positions, T from the modes), and T
// where P is smoothed again at every refresh.
void Multigrid::finish_set_up() {
  const bool keep_tentative =
      settings_.coarsening.smooth_prolongator && settings_.coarsening.update_prolongator;
  const auto release = [keep_tentative](auto& aggregates) {
    Rows().swap(aggregates.graph);
    decltype(aggregates.modes)().swap(aggregates.modes);
    if (!keep_tentative) decltype(aggregates.tentative)().swap(aggregates.tentative);
  };
  release(coarsening_->fine);
  for (auto& level : coarsening_->coarse) release(level);
  prolongators_ready_ = true;
}

void Multigrid::set_constraints(const std::vector<NodeConstraint>& constraints) {
  const auto same = [](const NodeConstraint& a, const NodeConstraint& b) {
    return a.node == b.node && a.filter == b.filter;
  };
  if (coarse_.empty() ||
      (constraints.size() == modes_constraints_.size() &&
       std::equal(constraints.begin(), constraints.end(), modes_constraints_.begin(), same)))
    return;
  modes_constraints_.assign(constraints.begin(), constraints.end());
  Aggregates<3>& fine = coarsening_->fine;
  fine.modes = rigid_body_modes(rest_positions_, constraints, fine.aggregate, coarse_[0].nodes(),
                                settings_.coarsening.modes);
  build_tentatives();
  prolongators_ready_ = false;  // the next factorize: a refresh, the modes improved, P smoothed
}

// ---- every step: the numbers ------------------------------------------------------------------

void Multigrid::factorize(const std::vector<Eigen::Matrix3d>& fine_blocks) {
  if (fine_blocks.size() != fine_.A.column.size())
    throw std::invalid_argument("multigrid: the matrix does not have the set-up pattern");
  ch09::on_one_thread(true, [&] {
    fine_.values = fine_blocks.data();
    refresh_rule_.decide(prolongators_ready_);
    if (!prolongators_ready_ && settings_.coarsening.improve_candidates > 0 && !coarse_.empty()) {
      // The rigid-body modes relaxed on the first matrix, then every T again from them.
      improve_modes(fine_, settings_.coarsening.improve_candidates, coarsening_->fine.modes);
      build_tentatives();
    }
  });
  const bool refresh = refresh_rule_.refreshed();
  auto own = [&](auto& level, std::size_t next, bool collective) {
    factorize_own(level, next, collective, refresh);
  };
  for_levels_from(fine_, coarse_, 0, true, refresh, own);
  // Read by every thread above; written after the last barrier of factorize_from's loops.
  ch09::on_one_thread(true, [&] {
    if (!prolongators_ready_) finish_set_up();
  });
}

// One level's own part of factorize(): its smoother every time (the coarsest level: its
// Cholesky factor); at a refresh also the smoothers' weights, the prolongator on the first
// refresh, and the Galerkin product that makes the next level's matrix.
template <int B>
void Multigrid::factorize_own(Level<B>& level, std::size_t next, bool collective, bool refresh) {
  const SmootherSettings& relax = settings_.relax;
  const bool gauss_seidel = relax.smoother == Smoother::GaussSeidel;
  ch09::for_parts(level.rows.part, collective, [&](int first, int last) {
    smoother_diagonal(level, gauss_seidel && relax.l1, first, last);
  });
  if (level.coarsest) {
    ch09::on_one_thread(collective, [&] { factorize_coarsest(level); });
    return;
  }
  if (!refresh) return;
  const CoarseningSettings& coarsening = settings_.coarsening;
  const bool new_prolongator =
      coarsening.smooth_prolongator && (coarsening.update_prolongator || !prolongators_ready_);
  ch09::on_one_thread(collective, [&] {
    estimate_spectrum(level, new_prolongator);
    if (new_prolongator)
      smooth_prolongator(level, aggregates_of(*coarsening_, level, next).tentative);
  });
  galerkin_product(level, coarse_[next], collective);
}

// rho(D^-1 A) where the prolongator's weight or a polynomial smoother needs it, and the
// smoother's weights from it. One thread.
template <int B>
void Multigrid::estimate_spectrum(Level<B>& level, bool new_prolongator) {
  const SmootherSettings& relax = settings_.relax;
  SmootherNumbers<B>& numbers = level.smoother;
  const bool gauss_seidel = relax.smoother == Smoother::GaussSeidel;
  const bool weights =
      !gauss_seidel && (relax.smoother == Smoother::Chebyshev || relax.jacobi_weight <= 0.0);
  if (new_prolongator || weights) {
    // Later estimates start from the last one's vector: a few iterations suffice.
    const int power = settings_.coarsening.power_iterations;
    const int iterations = prolongators_ready_ ? std::min(3, power) : power;
    const double rho = spectral_radius(level, iterations, !(gauss_seidel && relax.l1));
    if (new_prolongator) level.transfer.omega = 4.0 / (3.0 * rho);
    numbers.jacobi_weight = relax.jacobi_weight > 0.0 ? relax.jacobi_weight : 1.0 / rho;
    numbers.lambda_max = 1.1 * rho;  // the Rayleigh quotient is from below
  }
  if (relax.jacobi_weight > 0.0) numbers.jacobi_weight = relax.jacobi_weight;
  if (!gauss_seidel) polynomial_weights(numbers, relax);
}

// ---- every PCG iteration: the V-cycle ---------------------------------------------------------

void Multigrid::apply(const Eigen::VectorXd& r, Eigen::VectorXd& z) { apply(fine_, coarse_, r, z); }

// ---- for the lesson's costs per level ------------------------------------------------------

void Multigrid::factorize_level(int level, bool refresh) {
  auto own = [&](auto& l, std::size_t next, bool collective) {
    factorize_own(l, next, collective, refresh);
  };
  if (level == 0)
    for_levels_from(fine_, coarse_, 0, true, false, own);
  else
    for_levels_from(coarse_.at(level - 1), coarse_, level, true, false, own);
}

void Multigrid::cycle_from(int level) {
  if (level == 0) {
    v_cycle(fine_, coarse_, 0, fine_.vectors.b, fine_.vectors.x, true);
  } else {
    Level<kModes>& l = coarse_.at(level - 1);
    v_cycle(l, coarse_, level, l.vectors.b, l.vectors.x, true);
  }
}

}  // namespace fem::ch10
