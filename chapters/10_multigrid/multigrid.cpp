// Chapter 10: the smoothed-aggregation hierarchy. Set-up (constructor): aggregates, the
// tentative prolongator T from the rigid-body modes, the fixed patterns with their index
// tables and every level's fixed row blocks. Every step (prepare): the finest level's
// smoother; at a refresh also P = (I - w D^-1 A) T (the first time), A_c = P^T A P, the
// coarse smoothers and the coarsest Cholesky, numbers only. Every PCG iteration (apply): one
// V-cycle. prepare and apply run on the whole team: every loop a StaticShare (chapter 09's
// `omp for` written out) over fixed row blocks, each row written by one thread, every sum in a
// fixed order.
#include "chapters/10_multigrid/multigrid.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

#include "chapters/09_threads/parallel.hpp"

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
    const bool free =
        std::all_of(graph[i].begin(), graph[i].end(), [&](int j) { return aggregate[j] == -1; });
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

// ---- set-up: the fixed patterns and tables ------------------------------------------------

// The level's fixed row blocks, as chapter 09's RowChunks: equal numbers of stored blocks,
// their count a function of the level's size alone (a 6x6 row weighs about four 3x3 rows).
// Per row, the range of its blocks whose column lies in the row's own block: columns are
// sorted, so that range is contiguous.
template <int B>
void partition(Level<B>& level, const MultigridSettings& settings) {
  const auto& A = level.A;
  const int rows = level.nodes();
  const int min_rows = std::max(1, settings.block_rows * 9 / (B * B));
  const int count = std::clamp(rows / min_rows, 1, settings.max_blocks);
  const long long blocks = A.row_start.back();
  level.part.assign(count + 1, rows);
  level.part[0] = 0;
  for (int c = 1, i = 0; c < count; ++c) {
    const long long target = blocks * c / count;
    while (i < rows && A.row_start[i] < target) ++i;
    level.part[c] = i;
  }
  level.inner_begin.resize(rows);
  level.inner_end.resize(rows);
  for (int p = 0; p < count; ++p)
    for (int i = level.part[p]; i < level.part[p + 1]; ++i) {
      const auto first = A.column.begin() + A.row_start[i],
                 last = A.column.begin() + A.row_start[i + 1];
      level.inner_begin[i] =
          static_cast<int>(std::lower_bound(first, last, level.part[p]) - A.column.begin());
      level.inner_end[i] =
          static_cast<int>(std::lower_bound(first, last, level.part[p + 1]) - A.column.begin());
    }
  level.serial = rows < settings.serial_rows;
}

// The level's diagonal and transpose tables, its partition and its vectors.
template <int B>
void set_up_level(Level<B>& level, const MultigridSettings& settings) {
  const int n = level.nodes();
  level.diagonal.resize(n);
  for (int i = 0; i < n; ++i) level.diagonal[i] = level.A.find(i, i);
  level.transpose.resize(level.A.column.size());
  for (int i = 0; i < n; ++i)
    for (int k = level.A.row_start[i]; k < level.A.row_start[i + 1]; ++k)
      level.transpose[k] = level.A.find(level.A.column[k], i);
  partition(level, settings);
  level.inverse_diagonal.resize(n);
  level.l1.assign(n, Eigen::Matrix<double, B, 1>::Zero());
  for (Eigen::VectorXd* v : {&level.b, &level.x, &level.y, &level.work, &level.direction})
    v->setZero(level.dofs());
}

// The smoothed prolongator has the pattern of A T (row i: the aggregates of i's neighbours);
// T has one block per row, at (i, aggregate[i]); at_target says where each product A_k T
// lands. P^T's rows list P's blocks by coarse row, fine rows in increasing order.
template <int B>
void build_prolongator_pattern(Level<B>& fine, int count, bool smooth) {
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
  for (int i = 0; i < n; ++i) fine.tentative_block[i] = fine.P.find(i, fine.aggregate[i]);
  fine.at_target.clear();
  if (smooth)
    for (int i = 0; i < n; ++i)
      for (int k = A.row_start[i]; k < A.row_start[i + 1]; ++k)
        fine.at_target.push_back(fine.P.find(i, fine.aggregate[A.column[k]]));
  Rows transposed(count);
  std::vector<std::vector<int>> source(count);
  for (int i = 0; i < n; ++i)
    for (int m = fine.P.row_start[i]; m < fine.P.row_start[i + 1]; ++m) {
      transposed[fine.P.column[m]].push_back(i);
      source[fine.P.column[m]].push_back(m);
    }
  fine.PT = BlockCsr<kModes, B>(transposed);
  fine.pt_block.clear();
  for (const auto& s : source) fine.pt_block.insert(fine.pt_block.end(), s.begin(), s.end());
  fine.p_transposed.resize(fine.pt_block.size());
}

// A P on the pattern of A times P's, stored whole (each row written by its owner), and the
// place of every product A_k P_m, row by row in loop order.
template <int B>
void build_ap_pattern(Level<B>& fine) {
  const auto& A = fine.A;
  const auto& P = fine.P;
  const int n = fine.nodes();
  Rows rows(n);
  for (int i = 0; i < n; ++i) {
    for (int k = A.row_start[i]; k < A.row_start[i + 1]; ++k)
      for (int m = P.row_start[A.column[k]]; m < P.row_start[A.column[k] + 1]; ++m)
        rows[i].push_back(P.column[m]);
    sort_unique(rows[i]);
  }
  fine.AP = BlockCsr<B, kModes>(rows);
  fine.AP.blocks.clear();  // the values are stored transposed, in apt
  fine.apt.resize(fine.AP.column.size());
  fine.ap_target.clear();
  fine.ap_first.resize(n + 1);
  for (int i = 0; i < n; ++i) {
    fine.ap_first[i] = static_cast<int>(fine.ap_target.size());
    for (int k = A.row_start[i]; k < A.row_start[i + 1]; ++k)
      for (int m = P.row_start[A.column[k]]; m < P.row_start[A.column[k] + 1]; ++m)
        fine.ap_target.push_back(fine.AP.find(i, P.column[m]));
  }
  fine.ap_first[n] = static_cast<int>(fine.ap_target.size());
}

// The next level's pattern, P^T (A P), and the Galerkin tables by coarse row: for each entry
// of P^T's row c (block m of P in fine row i), the blocks of A P's row i from column c on,
// and where each product P_m^T (A P)_q lands in row c.
template <int B>
void build_galerkin_tables(Level<B>& fine, int count, Level<kModes>& coarse) {
  const auto& P = fine.P;
  const auto& AP = fine.AP;
  const auto& PT = fine.PT;
  Rows coarse_rows(count);
  for (int i = 0; i < fine.nodes(); ++i)
    for (int m = P.row_start[i]; m < P.row_start[i + 1]; ++m)
      for (int q = AP.row_start[i]; q < AP.row_start[i + 1]; ++q)
        coarse_rows[P.column[m]].push_back(AP.column[q]);
  for (auto& row : coarse_rows) sort_unique(row);
  coarse.A = BlockCsr<kModes, kModes>(coarse_rows);
  coarse.values = coarse.A.blocks.data();
  fine.galerkin_first.resize(P.column.size());
  for (int i = 0; i < fine.nodes(); ++i)
    for (int m = P.row_start[i]; m < P.row_start[i + 1]; ++m) {
      const auto first = AP.column.begin() + AP.row_start[i],
                 last = AP.column.begin() + AP.row_start[i + 1];
      fine.galerkin_first[m] =
          static_cast<int>(std::lower_bound(first, last, P.column[m]) - AP.column.begin());
    }
  fine.galerkin_target.clear();
  fine.galerkin_start.resize(count + 1);
  for (int c = 0; c < count; ++c) {
    fine.galerkin_start[c] = static_cast<int>(fine.galerkin_target.size());
    for (int e = PT.row_start[c]; e < PT.row_start[c + 1]; ++e) {
      const int i = PT.column[e], m = fine.pt_block[e];
      for (int q = fine.galerkin_first[m]; q < AP.row_start[i + 1]; ++q)
        fine.galerkin_target.push_back(coarse.A.find(c, AP.column[q]));
    }
  }
  fine.galerkin_start[count] = static_cast<int>(fine.galerkin_target.size());
}

// The transfer from `fine` to a new level `coarse`: all patterns and tables.
template <int B>
void build_transfer(Level<B>& fine, int count, const MultigridSettings& settings,
                    Level<kModes>& coarse) {
  fine.coarsest = false;
  coarse.graph = aggregate_graph(fine.graph, fine.aggregate, count);
  build_prolongator_pattern(fine, count, settings.smooth_prolongator);
  build_ap_pattern(fine);
  build_galerkin_tables(fine, count, coarse);
  set_up_level(coarse, settings);
  coarse.modes.resize(count);
}

template <int B>
void finish_coarsest(Level<B>& level) {
  level.coarsest = true;
  level.dense.setZero(level.dofs(), level.dofs());
  level.cholesky = Eigen::LLT<Eigen::MatrixXd>(level.dofs());  // storage for the factor
}

// ---- the team's loops ---------------------------------------------------------------------

// body(first, last) on each of the level's fixed row blocks: shared out between the threads
// of the team by a StaticShare (a static schedule, a barrier at its end: parallel.hpp) when
// collective, all on this thread otherwise (inside a `single`, where no loop may be shared).
template <int B, class Body>
void for_parts(const Level<B>& level, bool collective, Body&& body) {
  const int count = level.parts();
  if (collective) {
    for (const int p : ch09::StaticShare(count)) body(level.part[p], level.part[p + 1]);
  } else {
    for (int p = 0; p < count; ++p) body(level.part[p], level.part[p + 1]);
  }
}

// body() on one thread of the team (the others wait at the end), or here.
template <class Body>
void on_one_thread(bool collective, Body&& body) {
  if (collective) {
#pragma omp single
    body();
  } else {
    body();
  }
}

// ---- the numbers of one level -------------------------------------------------------------

// acc += M x for a small fixed-size block, column by column: Eigen leaves its own 6x6 product
// out of line (a call per block, a fifth of the V-cycle on the coarse level); this form
// inlines into a few vector multiply-adds.
template <int R, int C>
EIGEN_ALWAYS_INLINE void add_product(Eigen::Matrix<double, R, 1>& acc,
                                     const Eigen::Matrix<double, R, C>& M, const double* x) {
  for (int j = 0; j < C; ++j) acc += M.col(j) * x[j];
}

// out += L M^T for small fixed-size blocks, column by column: each column of out is a sum of
// L's columns, vectors of R = 6 rows in the Galerkin products (3-row columns vectorize poorly).
template <int R, int K, int C>
EIGEN_ALWAYS_INLINE void add_product_transposed(Eigen::Matrix<double, R, C>& out,
                                                const Eigen::Matrix<double, R, K>& L,
                                                const Eigen::Matrix<double, C, K>& M) {
  for (int c = 0; c < C; ++c) {
    Eigen::Matrix<double, R, 1> sum = out.col(c);
    for (int t = 0; t < K; ++t) sum += L.col(t) * M(c, t);
    out.col(c) = sum;
  }
}

// sum of A_k x_(column k) over the blocks [begin, end) of a row, in two independent sums: the
// products of a row then overlap instead of waiting on each other's additions.
template <int B>
EIGEN_ALWAYS_INLINE Eigen::Matrix<double, B, 1> row_product(const Level<B>& level,
                                                            const Eigen::VectorXd& x, int begin,
                                                            int end) {
  using Vector = Eigen::Matrix<double, B, 1>;
  Vector even = Vector::Zero(), odd = Vector::Zero();
  const int* column = level.A.column.data();
  int k = begin;
  for (; k + 1 < end; k += 2) {
    add_product(even, level.values[k], x.data() + B * column[k]);
    add_product(odd, level.values[k + 1], x.data() + B * column[k + 1]);
  }
  if (k < end) add_product(even, level.values[k], x.data() + B * column[k]);
  return even + odd;
}

// y = A x on a level, one block row at a time (set-up only: one thread).
template <int B>
void multiply(const Level<B>& level, const Eigen::VectorXd& x, Eigen::VectorXd& y) {
  const auto& A = level.A;
  for (int i = 0; i < level.nodes(); ++i)
    y.template segment<B>(B * i) = row_product(level, x, A.row_start[i], A.row_start[i + 1]);
}

// The largest eigenvalue of D^-1 A by power iteration, as the Rayleigh quotient
// x^T A x / x^T D x: from below. The first time from a fixed random start (deterministic),
// later from the last estimate's vector, which needs fewer iterations. D^-1 is the smoother's
// inverse diagonal unless that holds the l1 term. Uses the level's b and x as scratch; one
// thread (at a refresh only).
template <int B>
double spectral_radius(Level<B>& level, int iterations, bool plain_inverse) {
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
    for (int i = 0; i < level.nodes(); ++i) {
      const auto yi = y.template segment<B>(B * i);
      if (plain_inverse)
        x.template segment<B>(B * i) = level.inverse_diagonal[i] * yi;
      else
        x.template segment<B>(B * i) = level.values[level.diagonal[i]].inverse() * yi;
    }
    x /= x.norm();
  }
  level.start = x;
  return rho;
}

// P = T - w D^-1 (A T) on P's pattern; A T has one product per block of A because T has one
// block per row. One thread: on the first refresh only (or every one, update_prolongator).
template <int B>
void smooth_prolongator(Level<B>& level) {
  auto& P = level.P;
  const auto& A = level.A;
  for (auto& block : P.blocks) block.setZero();
  for (int i = 0; i < level.nodes(); ++i)
    for (int k = A.row_start[i]; k < A.row_start[i + 1]; ++k)
      P.blocks[level.at_target[k]].noalias() += level.values[k] * level.tentative[A.column[k]];
  for (int i = 0; i < level.nodes(); ++i) {
    const Eigen::Matrix<double, B, B> scaled =
        -level.omega * level.values[level.diagonal[i]].inverse();
    for (int m = P.row_start[i]; m < P.row_start[i + 1]; ++m) {
      const Eigen::Matrix<double, B, kModes> at = P.blocks[m];
      P.blocks[m].noalias() = scaled * at;
    }
    P.blocks[level.tentative_block[i]] += level.tentative[i];
  }
}

// P^T's blocks from P's, in P^T's row order (the restriction and the Galerkin product then
// stream through them as an SpMV does) and in P's (for A P, row by row). After every change
// of P (set-up, smoothing).
template <int B>
void transpose_prolongator(Level<B>& level) {
  for (std::size_t e = 0; e < level.pt_block.size(); ++e)
    level.PT.blocks[e] = level.P.blocks[level.pt_block[e]].transpose();
  for (std::size_t m = 0; m < level.P.blocks.size(); ++m)
    level.p_transposed[m] = level.P.blocks[m].transpose();
}

// A_c = P^T (A P) on the fixed patterns, by the team: A P by fine rows, each row by the
// thread that owns it; then the blocks on and right of the diagonal of A_c by the owner of
// each coarse row, summed over P^T's row in increasing fine row, the same order for any
// thread count; then the rest by symmetry (after the barrier: another row's blocks). A P is
// stored transposed, (A P)^T = P^T A (A symmetric), so that both products work on 6-row
// columns: (A P)_q^T += P_m^T A_k^T, then A_c += P^T_e ((A P)_q^T)^T.
template <int B>
void galerkin_product(Level<B>& level, Level<kModes>& coarse, bool collective) {
  const auto& A = level.A;
  const auto& P = level.P;
  const auto& AP = level.AP;
  for_parts(level, collective, [&](int first, int last) {
    for (int q = AP.row_start[first]; q < AP.row_start[last]; ++q) level.apt[q].setZero();
    const int* target = level.ap_target.data() + level.ap_first[first];
    for (int k = A.row_start[first]; k < A.row_start[last]; ++k) {
      const int j = A.column[k];
      for (int m = P.row_start[j]; m < P.row_start[j + 1]; ++m)
        add_product_transposed(level.apt[*target++], level.p_transposed[m], level.values[k]);
    }
  });
  auto& Ac = coarse.A;
  for_parts(coarse, collective, [&](int first, int last) {
    const int* target = level.galerkin_target.data() + level.galerkin_start[first];
    for (int c = first; c < last; ++c) {
      for (int k = coarse.diagonal[c]; k < Ac.row_start[c + 1]; ++k) Ac.blocks[k].setZero();
      for (int e = level.PT.row_start[c]; e < level.PT.row_start[c + 1]; ++e) {
        const int i = level.PT.column[e];
        for (int q = level.galerkin_first[level.pt_block[e]]; q < AP.row_start[i + 1]; ++q)
          add_product_transposed(Ac.blocks[*target++], level.PT.blocks[e], level.apt[q]);
      }
      // Modes an aggregate lacks: a zero row and column, given the identity (I - S).
      Ac.blocks[coarse.diagonal[c]].diagonal() += coarse.unused[c];
    }
  });
  for_parts(coarse, collective, [&](int first, int last) {
    for (int c = first; c < last; ++c)
      for (int k = Ac.row_start[c]; k < coarse.diagonal[c]; ++k)
        Ac.blocks[k] = Ac.blocks[coarse.transpose[k]].transpose();
  });
}

// The smoother's diagonal of rows [first, last): D_i^-1, or for Gauss-Seidel with the l1 term
// (D_i + diag(l1_i))^-1 with l1_i the row sums of |a| over the blocks outside the row's own
// block. That term makes hybrid Gauss-Seidel convergent for any SPD matrix and any partition
// (Baker et al. 2011, the l1 smoother).
template <int B>
void smoother_diagonal(Level<B>& level, bool l1, int first, int last) {
  using Vector = Eigen::Matrix<double, B, 1>;
  for (int i = first; i < last; ++i) {
    Eigen::Matrix<double, B, B> D = level.values[level.diagonal[i]];
    if (l1) {
      Vector sum = Vector::Zero();
      for (int k = level.A.row_start[i]; k < level.inner_begin[i]; ++k)
        sum += level.values[k].cwiseAbs().rowwise().sum();
      for (int k = level.inner_end[i]; k < level.A.row_start[i + 1]; ++k)
        sum += level.values[k].cwiseAbs().rowwise().sum();
      level.l1[i] = sum;
      D.diagonal() += sum;
    }
    level.inverse_diagonal[i] = D.inverse();
  }
}

// The weights of the polynomial smoothers, per step: d = alpha d + beta D^-1 r, x += d.
// Jacobi: alpha 0, beta w. Chebyshev on [lambda / ratio, lambda] (Saad, Iterative Methods,
// algorithm 12.1): beta_0 = 1 / theta, then rho_k = 1 / (2 sigma - rho_(k-1)),
// alpha_k = rho_k rho_(k-1), beta_k = 2 rho_k / delta.
template <int B>
void polynomial_weights(Level<B>& level, const MultigridSettings& settings) {
  auto& w = level.chebyshev;
  const bool chebyshev = settings.smoother == MultigridSettings::Smoother::Chebyshev;
  const int steps = chebyshev ? settings.chebyshev_degree * settings.sweeps : settings.sweeps;
  w.assign(2 * steps, 0.0);
  if (!chebyshev) {
    for (int k = 0; k < steps; ++k) w[2 * k + 1] = level.jacobi_weight;
    return;
  }
  const double upper = level.lambda_max, lower = upper / settings.chebyshev_ratio;
  const double theta = 0.5 * (upper + lower), delta = 0.5 * (upper - lower);
  const double sigma = theta / delta;
  double rho = 1.0 / sigma;
  w[1] = 1.0 / theta;
  for (int k = 1; k < steps; ++k) {
    const double next = 1.0 / (2.0 * sigma - rho);
    w[2 * k] = next * rho;
    w[2 * k + 1] = 2.0 * next / delta;
    rho = next;
  }
}

// ---- the smoothers, on the rows [first, last) of one block --------------------------------

// x = (D + L)^-1 b inside the block from x = 0: hybrid Gauss-Seidel's first forward sweep.
// The blocks right of the diagonal and outside the block multiply zeros, so only the lower
// part inside the block is read, and no other block's rows: no wait for another thread.
template <int B>
void gauss_seidel_from_zero(Level<B>& level, int first, int last, const Eigen::VectorXd& b,
                            Eigen::VectorXd& x) {
  for (int i = first; i < last; ++i) {
    const Eigen::Matrix<double, B, 1> r =
        b.template segment<B>(B * i) -
        row_product(level, x, level.inner_begin[i], level.diagonal[i]);
    x.template segment<B>(B * i).noalias() = level.inverse_diagonal[i] * r;
  }
}

// out_i = in_i + D_i^-1 (b - A x)_i, forward or backward through the block, where x is out on
// the block's rows already swept and in everywhere else: Gauss-Seidel inside the block,
// Jacobi between blocks (other blocks are read only from in, which no thread writes during
// the sweep). The backward sweep is the adjoint of the forward one: the V-cycle stays
// symmetric.
template <int B>
void gauss_seidel(Level<B>& level, int first, int last, const Eigen::VectorXd& b,
                  const Eigen::VectorXd& in, Eigen::VectorXd& out, bool forward) {
  const auto& A = level.A;
  for (int s = 0; s < last - first; ++s) {
    const int i = forward ? first + s : last - 1 - s;
    const int d = level.diagonal[i], end = A.row_start[i + 1];
    Eigen::Matrix<double, B, 1> sum;
    if (forward)
      sum = row_product(level, in, A.row_start[i], level.inner_begin[i]) +
            row_product(level, out, level.inner_begin[i], d) + row_product(level, in, d, end);
    else
      sum = row_product(level, in, A.row_start[i], d + 1) +
            row_product(level, out, d + 1, level.inner_end[i]) +
            row_product(level, in, level.inner_end[i], end);
    out.template segment<B>(B * i).noalias() =
        in.template segment<B>(B * i) +
        level.inverse_diagonal[i] * (b.template segment<B>(B * i) - sum);
  }
}

// A polynomial smoother's step k: d = alpha d + beta D^-1 (b - A in), out = in + d; from
// zero (in null) d = beta D^-1 b, out = d. Reads in on every row, writes out and d on its own.
template <int B>
void polynomial_step(Level<B>& level, int k, int first, int last, const Eigen::VectorXd& b,
                     const Eigen::VectorXd* in, Eigen::VectorXd& out) {
  const double alpha = level.chebyshev[2 * k], beta = level.chebyshev[2 * k + 1];
  const auto& A = level.A;
  if (!in) {
    for (int i = first; i < last; ++i) {
      auto d = level.direction.template segment<B>(B * i);
      d.noalias() = beta * (level.inverse_diagonal[i] * b.template segment<B>(B * i));
      out.template segment<B>(B * i) = d;
    }
    return;
  }
  for (int i = first; i < last; ++i) {
    const Eigen::Matrix<double, B, 1> r =
        b.template segment<B>(B * i) - row_product(level, *in, A.row_start[i], A.row_start[i + 1]);
    auto d = level.direction.template segment<B>(B * i);
    if (k == 0)
      d.noalias() = beta * (level.inverse_diagonal[i] * r);
    else
      d = alpha * d + beta * (level.inverse_diagonal[i] * r);
    out.template segment<B>(B * i) = in->template segment<B>(B * i) + d;
  }
}

// b - A x on rows [first, last) into the level's work vector. After exactly one forward
// Gauss-Seidel sweep from zero, (D + diag(l1) + L_block) x = b row by row, so the residual is
// l1 x minus the product of the blocks right of the diagonal and outside the block: the
// sweep and the residual together read the matrix once.
template <int B>
void residual(Level<B>& level, bool after_one_sweep, int first, int last, const Eigen::VectorXd& b,
              const Eigen::VectorXd& x) {
  const auto& A = level.A;
  for (int i = first; i < last; ++i) {
    auto r = level.work.template segment<B>(B * i);
    if (after_one_sweep)
      r = level.l1[i].cwiseProduct(x.template segment<B>(B * i)) -
          row_product(level, x, A.row_start[i], level.inner_begin[i]) -
          row_product(level, x, level.diagonal[i] + 1, A.row_start[i + 1]);
    else
      r = b.template segment<B>(B * i) - row_product(level, x, A.row_start[i], A.row_start[i + 1]);
  }
}

// b_c = P^T r on the coarse rows [first, last): each coarse row sums over its column of P,
// fine rows in increasing order.
template <int B>
void restrict_rows(const Level<B>& level, Level<kModes>& coarse, int first, int last) {
  for (int c = first; c < last; ++c) {
    Eigen::Matrix<double, kModes, 1> sum = Eigen::Matrix<double, kModes, 1>::Zero();
    for (int e = level.PT.row_start[c]; e < level.PT.row_start[c + 1]; ++e)
      add_product(sum, level.PT.blocks[e], level.work.data() + B * level.PT.column[e]);
    coarse.b.template segment<kModes>(kModes * c) = sum;
  }
}

// y = x + P x_c on rows [first, last) (x and y may be the same vector: each row reads its own).
template <int B>
void prolong_rows(Level<B>& level, const Level<kModes>& coarse, int first, int last,
                  const Eigen::VectorXd& x) {
  const auto& P = level.P;
  for (int i = first; i < last; ++i) {
    Eigen::Matrix<double, B, 1> sum = x.template segment<B>(B * i);
    for (int m = P.row_start[i]; m < P.row_start[i + 1]; ++m)
      add_product(sum, P.blocks[m], coarse.x.data() + kModes * P.column[m]);
    level.y.template segment<B>(B * i) = sum;
  }
}

// Gauss-Seidel on A x = 0 for each column of the modes, symmetric sweeps on the whole matrix
// in one thread: PyAMG's improve_candidates, once at set-up.
void relax_modes(const Level<3>& level, int sweeps,
                 std::vector<Eigen::Matrix<double, 3, kModes>>& modes) {
  const auto& A = level.A;
  const int n = level.nodes();
  for (int s = 0; s < 2 * sweeps; ++s)
    for (int t = 0; t < n; ++t) {
      const int i = s % 2 == 0 ? t : n - 1 - t;
      Eigen::Matrix<double, 3, kModes> sum = Eigen::Matrix<double, 3, kModes>::Zero();
      for (int k = A.row_start[i]; k < A.row_start[i + 1]; ++k)
        sum.noalias() += level.values[k] * modes[A.column[k]];
      modes[i] -= level.values[level.diagonal[i]].inverse() * sum;
    }
}

}  // namespace

// ---- set-up -------------------------------------------------------------------------------

namespace {

void check(const MultigridSettings& s) {
  if (s.modes != 3 && s.modes != kModes)
    throw std::invalid_argument("multigrid: modes must be 3 or 6");
  if (s.sweeps < 1 || s.max_levels < 1 || s.power_iterations < 1 || s.coarse_refresh < 1 ||
      s.max_blocks < 1 || s.block_rows < 1 || s.chebyshev_degree < 1 || s.improve_candidates < 0)
    throw std::invalid_argument(
        "multigrid: sweeps, levels, power iterations, coarse refresh, blocks, block rows and "
        "Chebyshev degree must be >= 1, candidate sweeps >= 0");
  if (!(s.chebyshev_ratio > 1.0) || !(s.refresh_growth >= 0.0) || !(s.jacobi_weight >= 0.0))
    throw std::invalid_argument(
        "multigrid: the Chebyshev ratio must exceed 1, growth and Jacobi weight be >= 0");
}

}  // namespace

Multigrid::Multigrid(const std::vector<int>& row_start, const std::vector<int>& column,
                     const Eigen::VectorXd& rest_positions,
                     const std::vector<NodeConstraint>& constraints,
                     const MultigridSettings& settings)
    : settings_(settings) {
  check(settings_);
  fine_.A.row_start = row_start;
  fine_.A.column = column;
  if (rest_positions.size() != 3 * fine_.nodes())
    throw std::invalid_argument("multigrid: rest positions do not match the pattern");
  set_up_level(fine_, settings_);

  std::mt19937 random(2015);  // the power iterations' start vectors: fixed, so deterministic
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  const auto start_vector = [&](Eigen::VectorXd& start, Eigen::Index size) {
    start.resize(size);
    for (Eigen::Index k = 0; k < size; ++k) start[k] = uniform(random);
  };
  start_vector(fine_.start, fine_.dofs());

  coarse_.reserve(settings_.max_levels);  // no reallocation: levels refer to their neighbours
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
  fine_.modes =
      rigid_body_modes(rest_positions, constraints, fine_.aggregate, count, settings_.modes);
  coarse_.emplace_back();
  build_transfer(fine_, count, settings_, coarse_.back());
  while (true) {
    Level<kModes>& level = coarse_.back();
    start_vector(level.start, level.dofs());
    level.aggregate = aggregate_nodes(level.graph, count);
    if (!worth_coarsening(level.dofs(), level.nodes(), count)) break;
    coarse_.emplace_back();
    build_transfer(coarse_[coarse_.size() - 2], count, settings_, coarse_.back());
  }
  finish_coarsest(coarse_.back());
  build_tentatives();
}

// T of every level from its modes, the next level's modes from T, and P = T until smoothed.
void Multigrid::build_tentatives() {
  const auto build = [](auto& level, Level<kModes>& coarse) {
    tentative_prolongator(level.modes, level.aggregate, coarse.nodes(), level.tentative,
                          coarse.modes, coarse.unused);
    for (auto& block : level.P.blocks) block.setZero();
    for (int i = 0; i < level.nodes(); ++i)
      level.P.blocks[level.tentative_block[i]] = level.tentative[i];
    transpose_prolongator(level);
  };
  if (coarse_.empty()) return;
  build(fine_, coarse_[0]);
  for (std::size_t l = 0; l + 1 < coarse_.size(); ++l) build(coarse_[l], coarse_[l + 1]);
}

// The rigid-body modes relaxed on the first matrix (A B = 0 by Gauss-Seidel), then every T
// again from them.
void Multigrid::improve_candidates() {
  relax_modes(fine_, settings_.improve_candidates, fine_.modes);
  build_tentatives();
}

// ---- every step ---------------------------------------------------------------------------

// The refresh rule, on one thread between barriers: it reads only V-cycle counts, the same
// for any thread count, so the decision (and the state) is too. Its yardstick is the count of
// the solve right after a refresh; after the first refresh, of the second solve, since the
// first one starts cold (no guess from earlier steps).
void Multigrid::decide_refresh() {
  const int last = cycles_;
  cycles_ = 0;
  ++prepares_;
  if (measure_next_ && prepares_ > 2) {
    cycles_after_refresh_ = last;
    measure_next_ = false;
  }
  ++since_refresh_;
  const bool grown = settings_.refresh_growth > 0.0 && !measure_next_ &&
                     last > settings_.refresh_growth * cycles_after_refresh_;
  refresh_ = !prolongators_ready_ || since_refresh_ >= settings_.coarse_refresh || grown;
  if (refresh_) {
    since_refresh_ = 0;
    ++refreshes_;
    measure_next_ = true;
  }
  refreshed_ = refresh_;
}

void Multigrid::prepare(const std::vector<Eigen::Matrix3d>& fine_blocks) {
  if (fine_blocks.size() != fine_.A.column.size())
    throw std::invalid_argument("multigrid: the matrix does not have the set-up pattern");
  on_one_thread(true, [&] {
    fine_.values = fine_blocks.data();
    decide_refresh();
    if (!prolongators_ready_ && settings_.improve_candidates > 0 && !coarse_.empty())
      improve_candidates();
  });
  prepare_level(fine_, 0, true);
  // Read by every thread above; written after the last barrier of prepare_level's loops.
  on_one_thread(true, [&] { prolongators_ready_ = true; });
}

// One level's numbers and, at a refresh, those of the levels below. A small level (serial)
// and the levels below it run on one thread.
template <int B>
void Multigrid::prepare_level(Level<B>& level, std::size_t next, bool collective) {
  if (collective && level.serial) {
    on_one_thread(true, [&] { prepare_level(level, next, false); });
    return;
  }
  prepare_own(level, next, collective, refresh_);
  if (refresh_ && !level.coarsest) prepare_level(coarse_[next], next + 1, collective);
}

// One level's own part of prepare(): its smoother every time (the coarsest level: its
// Cholesky factor); at a refresh also the polynomial smoother's weights, the prolongator on
// the first refresh, and the Galerkin product that makes the next level's matrix.
template <int B>
void Multigrid::prepare_own(Level<B>& level, std::size_t next, bool collective, bool refresh) {
  const bool gauss_seidel = settings_.smoother == MultigridSettings::Smoother::GaussSeidel;
  for_parts(level, collective, [&](int first, int last) {
    smoother_diagonal(level, gauss_seidel && settings_.l1, first, last);
  });
  if (level.coarsest) {
    on_one_thread(collective, [&] {
      const auto& A = level.A;
      for (int i = 0; i < level.nodes(); ++i)
        for (int k = A.row_start[i]; k < A.row_start[i + 1]; ++k)
          level.dense.template block<B, B>(B * i, B * A.column[k]) = level.values[k];
      level.cholesky.compute(level.dense);  // same size as reserved: no allocation
    });
    return;
  }
  if (!refresh) return;
  const bool new_prolongator =
      settings_.smooth_prolongator && (settings_.update_prolongator || !prolongators_ready_);
  on_one_thread(collective, [&] {
    const bool weights =
        !gauss_seidel && (settings_.smoother == MultigridSettings::Smoother::Chebyshev ||
                          settings_.jacobi_weight <= 0.0);
    if (new_prolongator || weights) {
      // Later estimates start from the last one's vector: a few iterations suffice.
      const int iterations = prolongators_ready_ ? std::min(3, settings_.power_iterations)
                                                 : settings_.power_iterations;
      const double rho = spectral_radius(level, iterations, !(gauss_seidel && settings_.l1));
      level.omega = new_prolongator ? 4.0 / (3.0 * rho) : level.omega;
      level.jacobi_weight = settings_.jacobi_weight > 0.0 ? settings_.jacobi_weight : 1.0 / rho;
      level.lambda_max = 1.1 * rho;  // the Rayleigh quotient is from below
    }
    if (settings_.jacobi_weight > 0.0) level.jacobi_weight = settings_.jacobi_weight;
    if (!gauss_seidel) polynomial_weights(level, settings_);
    if (new_prolongator) {
      smooth_prolongator(level);
      transpose_prolongator(level);
    }
  });
  galerkin_product(level, coarse_[next], collective);
}

// ---- the V-cycle --------------------------------------------------------------------------

// One V-cycle on `level` from a zero guess: b -> out (out may be the level's x). A small
// level (serial) and those below run on one thread; the coarsest is a dense solve.
template <int B>
void Multigrid::cycle(Level<B>& level, std::size_t next, const Eigen::VectorXd& b,
                      Eigen::VectorXd& out, bool collective) {
  if (collective && level.serial) {
    on_one_thread(true, [&] { cycle(level, next, b, out, false); });
    return;
  }
  if (level.coarsest) {
    on_one_thread(collective, [&] {
      out = b;
      if (level.cholesky.info() == Eigen::Success)
        level.cholesky.solveInPlace(out);
      else  // an overflowed system: say so through the residual, as the other chapters do
        out.setConstant(std::numeric_limits<double>::quiet_NaN());
    });
    return;
  }
  const bool gs = settings_.smoother == MultigridSettings::Smoother::GaussSeidel;
  const int steps = gs ? settings_.sweeps : static_cast<int>(level.chebyshev.size()) / 2;
  // Pre-smoothing from zero, ping-ponging between x and y: a step reads the last one's
  // result on every row and writes its own rows of the other vector.
  const Eigen::VectorXd* current = nullptr;
  for (int k = 0; k < steps; ++k) {
    Eigen::VectorXd& target = k % 2 == 0 ? level.x : level.y;
    for_parts(level, collective, [&](int first, int last) {
      if (gs && k == 0)
        gauss_seidel_from_zero(level, first, last, b, target);
      else if (gs)
        gauss_seidel(level, first, last, b, *current, target, true);
      else
        polynomial_step(level, k, first, last, b, current, target);
    });
    current = &target;
  }
  for_parts(level, collective, [&](int first, int last) {
    residual(level, gs && steps == 1, first, last, b, *current);
  });
  coarse_correction(level, next, *current, collective);
  // Post-smoothing from y = x + P x_c, the adjoint of the pre-smoothing, ending in out.
  current = &level.y;
  for (int k = 0; k < steps; ++k) {
    Eigen::VectorXd& target = (steps - k) % 2 == 1 ? out : level.work;
    for_parts(level, collective, [&](int first, int last) {
      if (gs)
        gauss_seidel(level, first, last, b, *current, target, false);
      else
        polynomial_step(level, k, first, last, b, current, target);
    });
    current = &target;
  }
}

// The residual in the level's work vector restricted, the next level's cycle, and its
// correction prolonged: y = x + P x_c.
template <int B>
void Multigrid::coarse_correction(Level<B>& level, std::size_t next, const Eigen::VectorXd& x,
                                  bool collective) {
  Level<kModes>& coarse = coarse_[next];
  for_parts(coarse, collective,
            [&](int first, int last) { restrict_rows(level, coarse, first, last); });
  cycle(coarse, next + 1, coarse.b, coarse.x, collective);
  for_parts(level, collective,
            [&](int first, int last) { prolong_rows(level, coarse, first, last, x); });
}

void Multigrid::count_cycle() {
#pragma omp master
  ++cycles_;  // read by the next prepare, many barriers later
}

void Multigrid::apply(const Eigen::VectorXd& r, Eigen::VectorXd& z) {
  count_cycle();
  cycle(fine_, 0, r, z, true);
}

// ---- for the lesson's costs per level ------------------------------------------------------

void Multigrid::prepare_level_only(int level, bool refresh) {
  const auto own = [&](auto& l, std::size_t next) {
    if (l.serial)
      on_one_thread(true, [&] { prepare_own(l, next, false, refresh); });
    else
      prepare_own(l, next, true, refresh);
  };
  if (level == 0)
    own(fine_, 0);
  else
    own(coarse_.at(level - 1), level);
}

void Multigrid::cycle_from(int level) {
  if (level == 0)
    cycle(fine_, 0, fine_.b, fine_.x, true);
  else
    cycle(coarse_.at(level - 1), level, coarse_.at(level - 1).b, coarse_.at(level - 1).x, true);
}

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

int Multigrid::level_parts(int level) const {
  return level == 0 ? fine_.parts() : coarse_.at(level - 1).parts();
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
