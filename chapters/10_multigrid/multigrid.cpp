// Chapter 10: the smoothed-aggregation hierarchy. Set-up (constructor): aggregates, the
// tentative prolongator T from the rigid-body modes, and the fixed patterns with their
// index tables. Every step (prepare): P = (I - w D^-1 A) T, A_c = P^T A P, smoothers and the
// coarsest Cholesky, numbers only. Every PCG iteration (apply): one V-cycle.
#include "chapters/10_multigrid/multigrid.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

namespace fem::ch10 {

namespace {

using Matrix6d = Eigen::Matrix<double, kModes, kModes>;
using Vector6d = Eigen::Matrix<double, kModes, 1>;
using Rows = std::vector<std::vector<int>>;  // a pattern under construction: columns per row

void sort_unique(std::vector<int>& v) {
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
}

// Standard aggregation (Vanek, Mandel & Brezina 1996; PyAMG's standard_aggregation) with
// every connection of the graph strong: PyAMG's default strength for smoothed aggregation
// is symmetric with theta = 0, which keeps all of them. So aggregates depend on the mesh
// alone and are built once. graph[i] lists i's neighbours (i included).
std::vector<int> aggregate_nodes(const Rows& graph, int& count) {
  const int n = static_cast<int>(graph.size());
  std::vector<int> aggregate(n, -1);
  count = 0;
  // 1: a node whose neighbours are all unaggregated seeds an aggregate with them.
  for (int i = 0; i < n; ++i) {
    if (aggregate[i] != -1) continue;
    const bool free = std::all_of(graph[i].begin(), graph[i].end(),
                                  [&](int j) { return aggregate[j] == -1; });
    if (!free) continue;
    for (const int j : graph[i]) aggregate[j] = count;
    aggregate[i] = count++;
  }
  // 2: the rest join a neighbouring aggregate of step 1.
  const std::vector<int> seeded = aggregate;
  for (int i = 0; i < n; ++i) {
    if (aggregate[i] != -1) continue;
    for (const int j : graph[i])
      if (seeded[j] != -1) {
        aggregate[i] = seeded[j];
        break;
      }
  }
  // 3: whatever is left (no aggregated neighbour) forms aggregates of its own.
  for (int i = 0; i < n; ++i) {
    if (aggregate[i] != -1) continue;
    for (const int j : graph[i])
      if (aggregate[j] == -1) aggregate[j] = count;
    aggregate[i] = count++;
  }
  return aggregate;
}

// The graph of the aggregates: two are neighbours when two of their nodes are. This, not the
// pattern of P^T A P (which also links aggregates two and three nodes apart), is what the next
// level aggregates: on the wider pattern its aggregates become so large (about 40 aggregates
// each on a 10k-node beam) that the coarsest level no longer represents the one above.
Rows aggregate_graph(const Rows& graph, const std::vector<int>& aggregate, int count) {
  Rows coarse(count);
  for (std::size_t i = 0; i < graph.size(); ++i)
    for (const int j : graph[i]) coarse[aggregate[i]].push_back(aggregate[j]);
  for (auto& row : coarse) sort_unique(row);
  return coarse;
}

// The near-null space of elasticity at the nodes: the 3 translations and the 3 rotations
// w x (X_i - c) about the aggregate's centroid c (centring changes nothing in the span but
// keeps the columns' scales close), filtered by S_i: a constrained direction is not free
// to move, so it is not part of the coarse space either.
std::vector<Eigen::Matrix<double, 3, kModes>> rigid_body_modes(
    const Eigen::VectorXd& X, const std::vector<NodeConstraint>& constraints,
    const std::vector<int>& aggregate, int count, int modes) {
  const int n = static_cast<int>(aggregate.size());
  std::vector<Eigen::Vector3d> centroid(count, Eigen::Vector3d::Zero());
  std::vector<int> members(count, 0);
  for (int i = 0; i < n; ++i) {
    centroid[aggregate[i]] += X.segment<3>(3 * i);
    ++members[aggregate[i]];
  }
  std::vector<Eigen::Matrix<double, 3, kModes>> modes_at(n);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d r = X.segment<3>(3 * i) - centroid[aggregate[i]] / members[aggregate[i]];
    auto& N = modes_at[i];
    N.setZero();
    N.leftCols<3>().setIdentity();
    if (modes > 3) {
      N.rightCols<3>() << 0.0, r.z(), -r.y(),  // w x r = -[r]_x w
          -r.z(), 0.0, r.x(),                  //
          r.y(), -r.x(), 0.0;
    }
  }
  for (const auto& c : constraints) modes_at[c.node] = c.filter * modes_at[c.node];
  return modes_at;
}

// T per aggregate: the aggregate's modes N orthonormalized, T = N V L^-1/2 from N^T N = V L V^T,
// and the coarse node's modes L^1/2 V^T (so that T times them is N). A mode whose eigenvalue
// is negligible (all nodes fixed, a collinear aggregate, 3 modes only) gets a zero column:
// its coarse row and column of P^T A P are zero and receive the identity instead.
template <int B>
void tentative_prolongator(const std::vector<Eigen::Matrix<double, B, kModes>>& modes,
                           const std::vector<int>& aggregate, int count,
                           std::vector<Eigen::Matrix<double, B, kModes>>& tentative,
                           std::vector<Matrix6d>& coarse_modes, std::vector<Vector6d>& unused) {
  std::vector<Matrix6d> gram(count, Matrix6d::Zero());
  for (std::size_t i = 0; i < aggregate.size(); ++i)
    gram[aggregate[i]].noalias() += modes[i].transpose() * modes[i];
  std::vector<Matrix6d> map(count);
  coarse_modes.resize(count);
  unused.resize(count);
  for (int a = 0; a < count; ++a) {
    const Eigen::SelfAdjointEigenSolver<Matrix6d> eigen(gram[a]);
    const Vector6d lambda = eigen.eigenvalues();
    const double largest = lambda.maxCoeff();
    for (int k = 0; k < kModes; ++k) {
      const bool kept = largest > 0.0 && lambda[k] > 1e-10 * largest;
      const double s = kept ? std::sqrt(lambda[k]) : 0.0;
      map[a].col(k) = kept ? Vector6d(eigen.eigenvectors().col(k) / s) : Vector6d::Zero();
      coarse_modes[a].row(k) = s * eigen.eigenvectors().col(k).transpose();
      unused[a][k] = kept ? 0.0 : 1.0;
    }
  }
  tentative.resize(aggregate.size());
  for (std::size_t i = 0; i < aggregate.size(); ++i)
    tentative[i].noalias() = modes[i] * map[aggregate[i]];
}

template <int B>
void set_diagonal(Level<B>& level) {
  level.diagonal.resize(level.nodes());
  for (int i = 0; i < level.nodes(); ++i) level.diagonal[i] = level.A.find(i, i);
  level.inverse_diagonal.resize(level.nodes());
  level.b.setZero(level.dofs());
  level.x.setZero(level.dofs());
  level.work.setZero(level.dofs());
}

// The transfer from `fine` to a new level `coarse`, all patterns and tables: the smoothed
// prolongator has the pattern of A T (row i: the aggregates of i's neighbours), A P the
// pattern of A times that, and P^T (A P) the next level's. Each table lists, in the order
// prepare() computes the products, the block where each product lands.
template <int B>
void build_transfer(Level<B>& fine, const std::vector<Eigen::Matrix<double, B, kModes>>& modes,
                    int count, bool smooth, Level<kModes>& coarse,
                    std::vector<Matrix6d>& coarse_modes) {
  fine.coarsest = false;
  coarse.graph = aggregate_graph(fine.graph, fine.aggregate, count);
  tentative_prolongator<B>(modes, fine.aggregate, count, fine.tentative, coarse_modes,
                           coarse.unused);
  const auto& A = fine.A;
  const int n = fine.nodes();
  Rows rows(n);
  for (int i = 0; i < n; ++i) {
    if (smooth)
      for (int k = A.row_start[i]; k < A.row_start[i + 1]; ++k)
        rows[i].push_back(fine.aggregate[A.column[k]]);
    else
      rows[i].push_back(fine.aggregate[i]);
    sort_unique(rows[i]);
  }
  fine.P = BlockCsr<B, kModes>(rows);
  fine.tentative_block.resize(n);
  for (int i = 0; i < n; ++i) {
    fine.tentative_block[i] = fine.P.find(i, fine.aggregate[i]);
    fine.P.blocks[fine.tentative_block[i]] = fine.tentative[i];  // P = T until smoothed
  }
  fine.at_target.clear();
  if (smooth)
    for (int i = 0; i < n; ++i)
      for (int k = A.row_start[i]; k < A.row_start[i + 1]; ++k)
        fine.at_target.push_back(fine.P.find(i, fine.aggregate[A.column[k]]));

  const auto& P = fine.P;
  for (int i = 0; i < n; ++i) {
    rows[i].clear();
    for (int k = A.row_start[i]; k < A.row_start[i + 1]; ++k)
      for (int m = P.row_start[A.column[k]]; m < P.row_start[A.column[k] + 1]; ++m)
        rows[i].push_back(P.column[m]);
    sort_unique(rows[i]);
  }
  fine.AP = BlockCsr<B, kModes>(rows);
  fine.ap_target.clear();
  for (int i = 0; i < n; ++i)
    for (int k = A.row_start[i]; k < A.row_start[i + 1]; ++k)
      for (int m = P.row_start[A.column[k]]; m < P.row_start[A.column[k] + 1]; ++m)
        fine.ap_target.push_back(fine.AP.find(i, P.column[m]) - fine.AP.row_start[i]);
  std::size_t longest = 0;  // A P's blocks: one row's worth, reused row after row
  for (const auto& r : rows) longest = std::max(longest, r.size());
  fine.AP.blocks.resize(longest);

  const auto& AP = fine.AP;
  Rows coarse_rows(count);
  for (int i = 0; i < n; ++i)
    for (int m = P.row_start[i]; m < P.row_start[i + 1]; ++m)
      for (int q = AP.row_start[i]; q < AP.row_start[i + 1]; ++q)
        coarse_rows[P.column[m]].push_back(AP.column[q]);
  for (auto& row : coarse_rows) sort_unique(row);
  coarse.A = BlockCsr<kModes, kModes>(coarse_rows);
  coarse.values = coarse.A.blocks.data();
  fine.galerkin_first.resize(P.column.size());
  fine.galerkin_target.clear();
  for (int i = 0; i < n; ++i)
    for (int m = P.row_start[i]; m < P.row_start[i + 1]; ++m) {
      const auto first = AP.column.begin() + AP.row_start[i],
                 last = AP.column.begin() + AP.row_start[i + 1];
      fine.galerkin_first[m] =
          static_cast<int>(std::lower_bound(first, last, P.column[m]) - AP.column.begin());
      for (int q = fine.galerkin_first[m]; q < AP.row_start[i + 1]; ++q)
        fine.galerkin_target.push_back(coarse.A.find(P.column[m], AP.column[q]));
    }
  fine.galerkin_mirror.clear();
  for (int c = 0; c < count; ++c)
    for (int k = coarse.A.row_start[c]; k < coarse.A.row_start[c + 1]; ++k)
      if (coarse.A.column[k] < c)
        fine.galerkin_mirror.push_back({k, coarse.A.find(coarse.A.column[k], c)});
  set_diagonal(coarse);
}

template <int B>
void finish_coarsest(Level<B>& level) {
  level.coarsest = true;
  level.dense.setZero(level.dofs(), level.dofs());
  level.cholesky = Eigen::LLT<Eigen::MatrixXd>(level.dofs());  // storage for the factor
}

// ---- the numbers of one level -------------------------------------------------------------

// sum of A_k x_(column k) over the blocks [begin, end) of a row, in two independent sums: the
// products of a row then overlap instead of waiting on each other's additions. That matters
// most in Gauss-Seidel, where a row cannot finish before the previous row's x_i is written.
template <int B>
EIGEN_ALWAYS_INLINE Eigen::Matrix<double, B, 1> row_product(const Level<B>& level,
                                                            const Eigen::VectorXd& x, int begin,
                                        int end) {
  using Vector = Eigen::Matrix<double, B, 1>;
  Vector even = Vector::Zero(), odd = Vector::Zero();
  const int* column = level.A.column.data();
  int k = begin;
  for (; k + 1 < end; k += 2) {
    even.noalias() += level.values[k] * x.template segment<B>(B * column[k]);
    odd.noalias() += level.values[k + 1] * x.template segment<B>(B * column[k + 1]);
  }
  if (k < end) even.noalias() += level.values[k] * x.template segment<B>(B * column[k]);
  return even + odd;
}

// y = A x on a level, one block row at a time.
template <int B>
void multiply(const Level<B>& level, const Eigen::VectorXd& x, Eigen::VectorXd& y) {
  const auto& A = level.A;
  for (int i = 0; i < level.nodes(); ++i)
    y.template segment<B>(B * i) = row_product(level, x, A.row_start[i], A.row_start[i + 1]);
}

// The largest eigenvalue of D^-1 A by power iteration from a fixed start (deterministic),
// as the Rayleigh quotient x^T A x / x^T D x: from below, so the weight 4 / (3 rho) is
// slightly large rather than small. Uses the level's b and x as scratch.
template <int B>
double spectral_radius(Level<B>& level, int iterations) {
  Eigen::VectorXd &x = level.x, &y = level.b;
  x = level.start;
  double rho = 0.0;
  for (int it = 0; it < iterations; ++it) {
    multiply(level, x, y);
    double xDx = 0.0;
    for (int i = 0; i < level.nodes(); ++i) {
      const auto xi = x.template segment<B>(B * i);
      xDx += xi.dot(level.values[level.diagonal[i]] * xi);
    }
    rho = x.dot(y) / xDx;
    for (int i = 0; i < level.nodes(); ++i)
      x.template segment<B>(B * i) = level.inverse_diagonal[i] * y.template segment<B>(B * i);
    x /= x.norm();
  }
  return rho;
}

// P = T - w D^-1 (A T) on P's pattern; A T has one product per block of A because T has one
// block per row.
template <int B>
void smooth_prolongator(Level<B>& level) {
  auto& P = level.P;
  const auto& A = level.A;
  for (auto& block : P.blocks) block.setZero();
  for (int i = 0; i < level.nodes(); ++i)
    for (int k = A.row_start[i]; k < A.row_start[i + 1]; ++k)
      P.blocks[level.at_target[k]].noalias() += level.values[k] * level.tentative[A.column[k]];
  for (int i = 0; i < level.nodes(); ++i) {
    const Eigen::Matrix<double, B, B> scaled = -level.omega * level.inverse_diagonal[i];
    for (int m = P.row_start[i]; m < P.row_start[i + 1]; ++m) {
      const Eigen::Matrix<double, B, kModes> at = P.blocks[m];
      P.blocks[m].noalias() = scaled * at;
    }
    P.blocks[level.tentative_block[i]] += level.tentative[i];
  }
}

// A_c = P^T (A P), both products on their fixed patterns through the tables.
template <int B>
void galerkin_product(Level<B>& level, Level<kModes>& coarse) {
  const auto& A = level.A;
  const auto& P = level.P;
  auto& AP = level.AP;
  // One row of A P at a time, in a buffer that stays in cache: row i of A P is needed only
  // by row i's products P_i^T (A P)_i, so the whole of A P is never stored.
  auto* row = AP.blocks.data();
  for (auto& block : coarse.A.blocks) block.setZero();
  const int* ap_target = level.ap_target.data();
  const int* target = level.galerkin_target.data();
  for (int i = 0; i < level.nodes(); ++i) {
    const int first = AP.row_start[i], length = AP.row_start[i + 1] - first;
    for (int q = 0; q < length; ++q) row[q].setZero();
    for (int k = A.row_start[i]; k < A.row_start[i + 1]; ++k) {
      const int j = A.column[k];
      for (int m = P.row_start[j]; m < P.row_start[j + 1]; ++m)
        row[*ap_target++].noalias() += level.values[k] * P.blocks[m];
    }
    for (int m = P.row_start[i]; m < P.row_start[i + 1]; ++m)
      for (int q = level.galerkin_first[m] - first; q < length; ++q)
        coarse.A.blocks[*target++].noalias() += P.blocks[m].transpose() * row[q];
  }
  for (const auto& [lower, upper] : level.galerkin_mirror)
    coarse.A.blocks[lower] = coarse.A.blocks[upper].transpose();
  for (int c = 0; c < coarse.nodes(); ++c)
    coarse.A.blocks[coarse.diagonal[c]].diagonal() += coarse.unused[c];
}

// One Gauss-Seidel sweep on blocks, forward or backward: x_i += D_i^-1 (b - A x)_i with the
// newest x. Forward before the coarse correction and backward after it make the V-cycle
// symmetric (the backward sweep is the adjoint of the forward one).
template <int B>
void gauss_seidel(const Level<B>& level, const Eigen::VectorXd& b, Eigen::VectorXd& x,
                  bool forward) {
  const auto& A = level.A;
  const int n = level.nodes();
  for (int s = 0; s < n; ++s) {
    const int i = forward ? s : n - 1 - s;
    const Eigen::Matrix<double, B, 1> r =
        b.template segment<B>(B * i) - row_product(level, x, A.row_start[i], A.row_start[i + 1]);
    x.template segment<B>(B * i).noalias() += level.inverse_diagonal[i] * r;
  }
}

// The first forward sweep from x = 0: the blocks right of the diagonal multiply zeros, so
// only the lower half is read. Afterwards b - A x is exactly -(strictly upper part) x, the
// other half: smoothing and residual together cost one SpMV instead of two.
template <int B>
void gauss_seidel_from_zero(const Level<B>& level, const Eigen::VectorXd& b, Eigen::VectorXd& x) {
  const auto& A = level.A;
  for (int i = 0; i < level.nodes(); ++i) {
    const Eigen::Matrix<double, B, 1> r =
        b.template segment<B>(B * i) - row_product(level, x, A.row_start[i], level.diagonal[i]);
    x.template segment<B>(B * i).noalias() = level.inverse_diagonal[i] * r;
  }
}

// x += w D^-1 (b - A x): damped block Jacobi, its own adjoint.
template <int B>
void jacobi(Level<B>& level, const Eigen::VectorXd& b, Eigen::VectorXd& x) {
  multiply(level, x, level.work);
  for (int i = 0; i < level.nodes(); ++i)
    x.template segment<B>(B * i).noalias() +=
        level.jacobi_weight * (level.inverse_diagonal[i] *
                               (b.template segment<B>(B * i) - level.work.template segment<B>(B * i)));
}

}  // namespace

// ---- set-up -------------------------------------------------------------------------------

Multigrid::Multigrid(const std::vector<int>& row_start, const std::vector<int>& column,
                     const Eigen::VectorXd& rest_positions,
                     const std::vector<NodeConstraint>& constraints,
                     const MultigridSettings& settings)
    : settings_(settings) {
  if (settings_.modes != 3 && settings_.modes != kModes)
    throw std::invalid_argument("multigrid: modes must be 3 or 6");
  if (settings_.sweeps < 1 || settings_.max_levels < 1 || settings_.power_iterations < 1 ||
      settings_.coarse_refresh < 1)
    throw std::invalid_argument(
        "multigrid: sweeps, levels, power iterations and coarse refresh must be >= 1");
  fine_.A.row_start = row_start;
  fine_.A.column = column;
  if (rest_positions.size() != 3 * fine_.nodes())
    throw std::invalid_argument("multigrid: rest positions do not match the pattern");
  set_diagonal(fine_);

  std::mt19937 random(2015);  // the power iterations' start vectors: fixed, so deterministic
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  const auto start_vector = [&](Eigen::VectorXd& start, Eigen::Index size) {
    start.resize(size);
    for (Eigen::Index k = 0; k < size; ++k) start[k] = uniform(random);
  };
  start_vector(fine_.start, fine_.dofs());

  coarse_.reserve(settings_.max_levels);  // no reallocation: levels refer to their neighbours
  std::vector<Matrix6d> modes;
  int count = 0;
  const auto worth_coarsening = [&](int dofs, int nodes, int aggregates) {
    return dofs > settings_.max_coarse_dofs && levels() < settings_.max_levels &&
           aggregates < nodes;
  };
  fine_.graph.resize(fine_.nodes());
  for (int i = 0; i < fine_.nodes(); ++i)
    fine_.graph[i].assign(column.begin() + row_start[i], column.begin() + row_start[i + 1]);
  fine_.aggregate = aggregate_nodes(fine_.graph, count);
  if (!worth_coarsening(fine_.dofs(), fine_.nodes(), count)) {
    finish_coarsest(fine_);
    return;
  }
  const auto fine_modes =
      rigid_body_modes(rest_positions, constraints, fine_.aggregate, count, settings_.modes);
  coarse_.emplace_back();
  build_transfer(fine_, fine_modes, count, settings_.smooth_prolongator, coarse_.back(), modes);
  while (true) {
    Level<kModes>& level = coarse_.back();
    start_vector(level.start, level.dofs());
    level.aggregate = aggregate_nodes(level.graph, count);
    if (!worth_coarsening(level.dofs(), level.nodes(), count)) break;
    const std::vector<Matrix6d> level_modes = modes;
    coarse_.emplace_back();
    build_transfer(coarse_[coarse_.size() - 2], level_modes, count, settings_.smooth_prolongator,
                   coarse_.back(), modes);
  }
  finish_coarsest(coarse_.back());
}

// ---- every step ---------------------------------------------------------------------------

template <int B>
void Multigrid::prepare_level(Level<B>& level, std::size_t next) {
  for (int i = 0; i < level.nodes(); ++i)
    level.inverse_diagonal[i] = level.values[level.diagonal[i]].inverse();
  if (level.coarsest) {
    const auto& A = level.A;
    for (int i = 0; i < level.nodes(); ++i)
      for (int k = A.row_start[i]; k < A.row_start[i + 1]; ++k)
        level.dense.template block<B, B>(B * i, B * A.column[k]) = level.values[k];
    level.cholesky.compute(level.dense);  // same size as reserved: no allocation
    return;
  }
  const bool new_prolongator =
      settings_.smooth_prolongator && (settings_.update_prolongator || !prolongators_ready_);
  const bool jacobi_smoother = settings_.smoother == MultigridSettings::Smoother::Jacobi;
  if (new_prolongator || (jacobi_smoother && settings_.jacobi_weight <= 0.0)) {
    const double rho = spectral_radius(level, settings_.power_iterations);
    level.omega = 4.0 / (3.0 * rho);
    level.jacobi_weight = settings_.jacobi_weight > 0.0 ? settings_.jacobi_weight : 1.0 / rho;
  }
  if (jacobi_smoother && settings_.jacobi_weight > 0.0) level.jacobi_weight = settings_.jacobi_weight;
  if (new_prolongator) smooth_prolongator(level);
  galerkin_product(level, coarse_[next]);
}

void Multigrid::prepare(const std::vector<Eigen::Matrix3d>& fine_blocks) {
  if (fine_blocks.size() != fine_.A.column.size())
    throw std::invalid_argument("multigrid: the matrix does not have the set-up pattern");
  fine_.values = fine_blocks.data();
  if (prepares_++ % settings_.coarse_refresh != 0 && !fine_.coarsest) {
    for (int i = 0; i < fine_.nodes(); ++i)
      fine_.inverse_diagonal[i] = fine_.values[fine_.diagonal[i]].inverse();
    return;
  }
  prepare_level(fine_, 0);
  for (std::size_t l = 0; l < coarse_.size(); ++l) prepare_level(coarse_[l], l + 1);
  prolongators_ready_ = true;
}

// ---- the V-cycle --------------------------------------------------------------------------

template <int B>
void Multigrid::cycle(Level<B>& level, std::size_t next, const Eigen::VectorXd& b,
                      Eigen::VectorXd& x) {
  if (level.coarsest) {
    x = b;
    if (level.cholesky.info() == Eigen::Success)
      level.cholesky.solveInPlace(x);
    else  // an overflowed system: say so through the residual, as the other chapters do
      x.setConstant(std::numeric_limits<double>::quiet_NaN());
    return;
  }
  const bool gauss_seidel_smoother = settings_.smoother == MultigridSettings::Smoother::GaussSeidel;
  const auto& A = level.A;
  if (gauss_seidel_smoother) {
    gauss_seidel_from_zero(level, b, x);
    for (int s = 1; s < settings_.sweeps; ++s) gauss_seidel(level, b, x, true);
  } else {
    x.setZero();
    for (int s = 0; s < settings_.sweeps; ++s) jacobi(level, b, x);
  }
  // After one sweep from zero the residual is the upper half's product, computed row by row
  // below; otherwise a full product first.
  const bool upper_residual = gauss_seidel_smoother && settings_.sweeps == 1;
  if (!upper_residual) {
    multiply(level, x, level.work);
    level.work = b - level.work;
  }
  // Restrict the residual: b_c = P^T (b - A x).
  Level<kModes>& coarse = coarse_[next];
  coarse.b.setZero();
  const auto& P = level.P;
  for (int i = 0; i < level.nodes(); ++i) {
    Eigen::Matrix<double, B, 1> r;
    if (upper_residual) {
      r = -row_product(level, x, level.diagonal[i] + 1, A.row_start[i + 1]);
    } else {
      r = level.work.template segment<B>(B * i);
    }
    for (int m = P.row_start[i]; m < P.row_start[i + 1]; ++m)
      coarse.b.template segment<kModes>(kModes * P.column[m]).noalias() +=
          P.blocks[m].transpose() * r;
  }
  cycle(coarse, next + 1, coarse.b, coarse.x);
  // Prolong the correction: x += P x_c.
  for (int i = 0; i < level.nodes(); ++i) {
    Eigen::Matrix<double, B, 1> sum = Eigen::Matrix<double, B, 1>::Zero();
    for (int m = P.row_start[i]; m < P.row_start[i + 1]; ++m)
      sum.noalias() += P.blocks[m] * coarse.x.template segment<kModes>(kModes * P.column[m]);
    x.template segment<B>(B * i) += sum;
  }
  for (int s = 0; s < settings_.sweeps; ++s)
    gauss_seidel_smoother ? gauss_seidel(level, b, x, false) : jacobi(level, b, x);
}

void Multigrid::apply(const Eigen::VectorXd& r, Eigen::VectorXd& z) { cycle(fine_, 0, r, z); }

// ---- reports ------------------------------------------------------------------------------

int Multigrid::level_dofs(int level) const {
  return level == 0 ? fine_.dofs() : coarse_.at(level - 1).dofs();
}

long long Multigrid::level_blocks(int level) const {
  return static_cast<long long>(level == 0 ? fine_.A.column.size()
                                           : coarse_.at(level - 1).A.column.size());
}

long long Multigrid::prolongator_blocks(int level) const {
  return static_cast<long long>(level == 0 ? fine_.P.column.size()
                                           : coarse_.at(level - 1).P.column.size());
}

Eigen::SparseMatrix<double> Multigrid::level_matrix(int level) const {
  if (level == 0) return fine_.A.to_sparse(fine_.values, fine_.dofs());
  const auto& l = coarse_.at(level - 1);
  return l.A.to_sparse(l.values, l.dofs());
}

Eigen::SparseMatrix<double> Multigrid::prolongator(int level) const {
  const int coarse_dofs = level_dofs(level + 1);
  if (level == 0) return fine_.P.to_sparse(coarse_dofs);
  const auto& l = coarse_.at(level - 1);
  return l.P.to_sparse(coarse_dofs);
}

Eigen::VectorXd Multigrid::unused_modes(int level) const {
  const auto& l = coarse_.at(level - 1);
  Eigen::VectorXd u(l.dofs());
  for (int c = 0; c < l.nodes(); ++c) u.segment<kModes>(kModes * c) = l.unused[c];
  return u;
}

}  // namespace fem::ch10
