// Chapter 09: one linearized backward Euler step (Baraff & Witkin 1998),
//   A dv = b,  A = M - h df/dv - h^2 df/dx,  b = h (f + h df/dx v),
// with velocity constraints by the filter S of the PPCG method (Tamstorf et al. 2015):
//   (S A S^T + I - S) y = S (b - A z),  dv = y + z.
// Chapter 09 changes who does the work: every phase but the constraints runs on all the
// threads OpenMP is given. Three rules keep it correct and the result independent of the
// thread count:
//  - a thread writes only what it owns: the rows of its chunks, or its elements' slots;
//  - every parallel loop over rows goes over the same fixed chunks (RowChunks);
//  - a sum over the mesh is a sum of per-chunk sums added in chunk order, never an
//    OpenMP reduction (whose order of combination depends on the threads).
#include "chapters/09_threads/stepper.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "chapters/09_threads/parallel.hpp"

namespace fem::ch09 {

// ---- the block sparse matrix ------------------------------------------------------

BlockSparseMatrix::BlockSparseMatrix(const std::vector<std::vector<int>>& adjacency) {
  row_start.assign(1, 0);
  for (const auto& row : adjacency) {
    column.insert(column.end(), row.begin(), row.end());
    row_start.push_back(static_cast<int>(column.size()));
  }
  blocks.assign(column.size(), Eigen::Matrix3d::Zero());
}

int BlockSparseMatrix::find(int i, int j) const {
  const auto first = column.begin() + row_start[i], last = column.begin() + row_start[i + 1];
  const auto it = std::lower_bound(first, last, j);
  return (it != last && *it == j) ? static_cast<int>(it - column.begin()) : -1;
}

void BlockSparseMatrix::multiply_rows(const Eigen::VectorXd& x, Eigen::VectorXd& y, int first,
                                      int last) const {
  for (int i = first; i < last; ++i) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();  // in registers: y_i is written once
    for (int k = row_start[i]; k < row_start[i + 1]; ++k)
      sum.noalias() += blocks[k] * x.segment<3>(3 * column[k]);
    y.segment<3>(3 * i) = sum;
  }
}

void BlockSparseMatrix::multiply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const {
  multiply_rows(x, y, 0, block_rows());
}

void BlockSparseMatrix::multiply_upper(const Eigen::VectorXd& x, Eigen::VectorXd& y) const {
  y.setZero();
  const int n = block_rows();
  for (int i = 0; i < n; ++i) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    const Eigen::Vector3d xi = x.segment<3>(3 * i);
    for (int k = row_start[i]; k < row_start[i + 1]; ++k) {
      const int j = column[k];
      if (j < i) continue;  // only the upper blocks are read
      sum.noalias() += blocks[k] * x.segment<3>(3 * j);
      if (j != i) y.segment<3>(3 * j).noalias() += blocks[k].transpose() * xi;
    }
    y.segment<3>(3 * i) += sum;
  }
}

BlockSparseMatrix BlockSparseMatrix::upper() const {
  BlockSparseMatrix u;
  u.row_start.assign(1, 0);
  for (int i = 0; i < block_rows(); ++i) {
    for (int k = row_start[i]; k < row_start[i + 1]; ++k) {
      if (column[k] < i) continue;
      u.column.push_back(column[k]);
      u.blocks.push_back(blocks[k]);
    }
    u.row_start.push_back(static_cast<int>(u.column.size()));
  }
  return u;
}

Eigen::SparseMatrix<double> BlockSparseMatrix::to_sparse() const {
  std::vector<Eigen::Triplet<double>> t;
  for (int i = 0; i < block_rows(); ++i)
    for (int k = row_start[i]; k < row_start[i + 1]; ++k)
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) t.emplace_back(3 * i + r, 3 * column[k] + c, blocks[k](r, c));
  Eigen::SparseMatrix<double> m(3 * block_rows(), 3 * block_rows());
  m.setFromTriplets(t.begin(), t.end());
  return m;
}

RowChunks::RowChunks(const BlockSparseMatrix& pattern) {
  // Equal numbers of blocks rather than of rows: the SpMV, the largest loop, costs per
  // block. The boundaries depend on the pattern only.
  // Fewer chunks on a small mesh (at least kMinRows rows each), where a chunk's fixed cost
  // would show; still a function of the mesh alone.
  const int rows = pattern.block_rows();
  const int count = std::clamp(rows / kMinRows, 1, kMaxCount);
  const long long blocks = pattern.row_start.back();
  start.assign(count + 1, rows);
  start[0] = 0;
  int i = 0;
  for (int c = 1; c < count; ++c) {
    const long long target = blocks * c / count;
    while (i < rows && pattern.row_start[i] < target) ++i;
    start[c] = i;
  }
}

namespace {

// The sum of per-chunk partial sums, in chunk order. Every thread adds them up itself
// after the barrier (64 additions): the same value on every thread, and no extra barrier
// to hand a result from one thread to the others.
double sum_in_order(const std::vector<double>& partial) {
  double sum = 0.0;
  for (const double p : partial) sum += p;
  return sum;
}

}  // namespace

// ---- the element kernels --------------------------------------------------------------

ElementShape make_element_shape(const ElementRest& rest, const Lame& lame) {
  return {rest.Dm_inv, rest.volume * lame.mu, rest.volume * lame.lambda};
}

namespace {

// Below this det F / (|F|^2 / 3)^(3/2) (1 for a rotation, 0 for a flat element) Newton is
// not asked: an inverted element's polar rotation has det -1 and common/ flips it to +1
// by a convention that only the SVD knows, and near det F = 0 the sign itself is rounding.
constexpr double kMinRelativeDet = 1e-4;
// Newton converges quadratically: once a step is below 1e-8 rad, the next would be below
// about 1e-16, rounding. The cap stops a start far from the answer (then the SVD decides).
constexpr double kConvergedStep = 1e-8;
constexpr int kMaxIterations = 12;

// |q|^2 R(q / |q|), the rotation of a quaternion that need not be unit, without a division.
Eigen::Matrix3d scaled_rotation(const Eigen::Quaterniond& q) {
  const double w = q.w(), x = q.x(), y = q.y(), z = q.z();
  Eigen::Matrix3d R;
  R << w * w + x * x - y * y - z * z, 2.0 * (x * y - w * z), 2.0 * (x * z + w * y),  //
      2.0 * (x * y + w * z), w * w - x * x + y * y - z * z, 2.0 * (y * z - w * x),   //
      2.0 * (x * z - w * y), 2.0 * (y * z + w * x), w * w - x * x - y * y + z * z;
  return R;
}

// x = H^-1 b for a symmetric 3x3 H by its adjugate: no pivoting, no LU. False where H is not
// positive definite (Sylvester's criterion) or det H <= min_det, nearly singular.
bool solve_positive_definite(const Eigen::Matrix3d& H, const Eigen::Vector3d& b, double min_det,
                             Eigen::Vector3d& x) {
  const double minor2 = H(0, 0) * H(1, 1) - H(0, 1) * H(0, 1);
  const double det = H.determinant();
  if (!(H(0, 0) > 0.0 && minor2 > 0.0 && det > min_det)) return false;  // also NaN
  Eigen::Matrix3d adjugate;
  adjugate << H(1, 1) * H(2, 2) - H(1, 2) * H(1, 2), H(0, 2) * H(1, 2) - H(0, 1) * H(2, 2),
      H(0, 1) * H(1, 2) - H(0, 2) * H(1, 1),  //
      H(0, 2) * H(1, 2) - H(0, 1) * H(2, 2), H(0, 0) * H(2, 2) - H(0, 2) * H(0, 2),
      H(0, 1) * H(0, 2) - H(0, 0) * H(1, 2),  //
      H(0, 1) * H(1, 2) - H(0, 2) * H(1, 1), H(0, 1) * H(0, 2) - H(0, 0) * H(1, 2), minor2;
  x.noalias() = adjugate * b;
  x /= det;
  return true;
}

}  // namespace

int newton_polar_rotation(const Eigen::Matrix3d& F, Eigen::Quaterniond& q) {
  const double scale2 = F.squaredNorm() / 3.0;
  if (!(F.determinant() > kMinRelativeDet * scale2 * std::sqrt(scale2))) return -1;  // or NaN
  // R = R_q exp([w]) makes R^T F symmetric: linearized, H w = axial(A - A^T) with
  // A = R_q^T F and H = tr(S) I - S, S = sym(A). H's eigenvalues are the sums of pairs of
  // S's, so H is positive definite exactly where S is (det S > 0): near the polar rotation.
  // w does not change when A is scaled, so q need not be unit during the iteration: one
  // normalization at the end instead of a square root and a division per iteration.
  for (int k = 1; k <= kMaxIterations; ++k) {
    const Eigen::Matrix3d A = scaled_rotation(q).transpose() * F;
    const Eigen::Vector3d axial(A(2, 1) - A(1, 2), A(0, 2) - A(2, 0), A(1, 0) - A(0, 1));
    Eigen::Matrix3d H = -0.5 * (A + A.transpose());
    H.diagonal().array() += A.trace();
    // A, and so H, carries the factor |q|^2: the singularity test is scaled with it.
    const double q2 = q.squaredNorm();
    Eigen::Vector3d w;
    if (!solve_positive_definite(H, axial, 1e-12 * q2 * q2 * q2 * scale2 * std::sqrt(scale2), w))
      return -1;
    // exp([w]) to second order as the quaternion (1, w/2): a rotation once normalized, and
    // Newton's quadratic convergence is kept.
    q = q * Eigen::Quaterniond(1.0, 0.5 * w.x(), 0.5 * w.y(), 0.5 * w.z());
    if (w.squaredNorm() < kConvergedStep * kConvergedStep) {
      q.normalize();
      return k;
    }
  }
  return -1;
}

Eigen::Matrix3d fast_polar_rotation(const Eigen::Matrix3d& F, Eigen::Quaterniond& q,
                                    long long& fallbacks) {
  Eigen::Quaterniond start = q;
  if (newton_polar_rotation(F, start) > 0) {
    q = start;
    return q.toRotationMatrix();
  }
  ++fallbacks;
  const Eigen::Matrix3d R = polar_rotation(F);
  q = Eigen::Quaterniond(R);
  return R;
}

Eigen::Matrix<double, 3, 4> rotated_gradients(const Eigen::Matrix3d& R,
                                              const Eigen::Matrix3d& Dm_inv) {
  // g_1..g_3 are the rows of Dm^-1 and g_0 = -(g_1 + g_2 + g_3): r = R [g_0 .. g_3].
  Eigen::Matrix<double, 3, 4> r;
  r.rightCols<3>().noalias() = R * Dm_inv.transpose();
  r.col(0) = -r.rightCols<3>().rowwise().sum();
  return r;
}

void stiffness_blocks(const Eigen::Matrix<double, 3, 4>& r, double mu_volume,
                      double lambda_volume, std::array<Eigen::Matrix3d, 10>& K) {
  for (std::size_t p = 0; p < kUpperPairs.size(); ++p) {
    const auto ra = r.col(kUpperPairs[p][0]), rb = r.col(kUpperPairs[p][1]);
    // One outer product serves both rank-one terms: r_b r_a^T and its transpose.
    const Eigen::Matrix3d outer = rb * ra.transpose();
    K[p] = mu_volume * outer + lambda_volume * outer.transpose();
    K[p].diagonal().array() += mu_volume * ra.dot(rb);
  }
}

// ---- the stepper ------------------------------------------------------------------------

ThreadsStepper::ThreadsStepper(const Scene& scene, const SolverSettings& settings,
                               ElementParallelism element_parallelism)
    : Stepper(scene),
      scene_(scene),
      model_(scene),
      settings_(settings),
      element_parallelism_(element_parallelism) {
  const int n = model_.dofs;
  const Lame lame =
      lame_from_young_poisson(scene.material.youngs_modulus, scene.material.poisson_ratio);
  shapes_.reserve(model_.tets.size());
  for (const ElementRest& rest : model_.rest) shapes_.push_back(make_element_shape(rest, lame));
  // The rest shape's, as a start: a stepper created on a deformed body (the viewer switching
  // chapters) starts cold, and Newton or the SVD fallback finds the rotations.
  rotations_.assign(model_.tets.size(), Eigen::Quaterniond::Identity());
  previous_rotations_ = rotations_;

  // The pattern, once: a block per pair of nodes that share a tetrahedron. Where each
  // element's 16 blocks sit, the diagonal blocks and the transposes are found once too.
  A_ = BlockSparseMatrix(node_adjacency(scene.mesh));
  element_blocks_.resize(model_.tets.size());
  for (std::size_t e = 0; e < model_.tets.size(); ++e)
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b)
        element_blocks_[e][4 * a + b] = A_.find(model_.tets[e][a], model_.tets[e][b]);
  diagonal_block_.resize(model_.num_nodes);
  for (int i = 0; i < model_.num_nodes; ++i) diagonal_block_[i] = A_.find(i, i);
  transpose_block_.resize(A_.blocks.size());
  for (int i = 0; i < model_.num_nodes; ++i)
    for (int k = A_.row_start[i]; k < A_.row_start[i + 1]; ++k)
      transpose_block_[k] = A_.find(A_.column[k], i);
  chunks_ = RowChunks(A_);

  // The gather tables: the element-to-block table read the other way round, by node and
  // by block. Filled in element order, so that each sum adds in the serial pass's order.
  const int num_elements = static_cast<int>(model_.tets.size());
  const auto invert = [](int rows, int terms, const auto& target, std::vector<int>& start,
                         std::vector<int>& list) {
    start.assign(rows + 1, 0);
    for (int t = 0; t < terms; ++t) ++start[target(t) + 1];
    std::partial_sum(start.begin(), start.end(), start.begin());
    list.resize(terms);
    std::vector<int> next(start.begin(), start.end() - 1);
    for (int t = 0; t < terms; ++t) list[next[target(t)]++] = t;
  };
  if (element_parallelism_ == ElementParallelism::gather) {
    element_rhs_.resize(num_elements);
    element_K_.resize(num_elements);
    invert(model_.num_nodes, 4 * num_elements, [this](int t) { return model_.tets[t / 4][t % 4]; },
           node_corner_start_, node_corners_);
    invert(static_cast<int>(A_.blocks.size()), 16 * num_elements,
           [this](int t) { return element_blocks_[t / 16][t % 16]; }, block_term_start_,
           block_terms_);
  } else {
    // Groups of kGroup consecutive elements rather than single elements: a group keeps
    // the mesh order's locality (its elements share nodes, hence cache lines). Greedily,
    // each group takes the first colour that no group sharing one of its nodes has.
    const int groups = (num_elements + kGroup - 1) / kGroup;
    std::vector<std::vector<int>> node_colours(model_.num_nodes);
    std::vector<int> colour(groups);
    int colours = 0;
    for (int g = 0; g < groups; ++g) {
      const int first = g * kGroup, last = std::min(num_elements, first + kGroup);
      const auto taken = [&](int candidate) {
        for (int e = first; e < last; ++e)
          for (int a = 0; a < 4; ++a) {
            const auto& used = node_colours[model_.tets[e][a]];
            if (std::find(used.begin(), used.end(), candidate) != used.end()) return true;
          }
        return false;
      };
      int c = 0;
      while (taken(c)) ++c;
      colour[g] = c;
      colours = std::max(colours, c + 1);
      for (int e = first; e < last; ++e)
        for (int a = 0; a < 4; ++a) node_colours[model_.tets[e][a]].push_back(c);
    }
    invert(colours, groups, [&colour](int g) { return colour[g]; }, colour_start_, colour_order_);
  }
  pcg_ = ParallelPcg(A_, diagonal_block_, scene_.constraints);
  b_.resize(n);
  y_.setZero(n);
}

void ThreadsStepper::step(State& state) {
  PhaseTimer total(profile_.step);
  {
    PhaseTimer t(profile_.compose);
    start_system(state);
  }
  {
    // The fused pass: rotations, forces and the blocks of df/dx, written into A and b. It
    // does the work of the earlier chapters' forces, df/dx and composition phases and is
    // reported under forces; dfdx stays zero, because no df/dx is built.
    PhaseTimer t(profile_.forces);
    element_pass(state);
  }
  profile_.dfdx = PhaseCost{};
  {
    PhaseTimer t(profile_.constraints);
    apply_constraints(state);
  }
  {
    PhaseTimer t(profile_.solve);
    solve();
  }
  state.v += dv_;
  state.x += scene_.dt * state.v;
}

void ThreadsStepper::start_system(const State& state) {
  const double h = scene_.dt, alpha = scene_.damping.alpha;
  // What the elements do not touch: A = (1 + h alpha) M, b = h (f_gravity - alpha M v + f_ext),
  // row by row on the thread that owns the row.
  const double mass_factor = 1.0 + h * alpha;
  run_parallel([&] {
#pragma omp for schedule(static)
    for (int c = 0; c < chunks_.count(); ++c) {
      for (int k = A_.row_start[chunks_.start[c]]; k < A_.row_start[chunks_.start[c + 1]]; ++k)
        A_.blocks[k].setZero();
      for (int i = chunks_.start[c]; i < chunks_.start[c + 1]; ++i)
        A_.blocks[diagonal_block_[i]].diagonal() =
            mass_factor * model_.lumped_mass.segment<3>(3 * i);
      const int first = 3 * chunks_.start[c], size = 3 * chunks_.rows(c);
      b_.segment(first, size).noalias() =
          h * model_.gravity_force.segment(first, size) -
          (h * alpha) * model_.lumped_mass.segment(first, size).cwiseProduct(state.v.segment(first, size));
    }
  });
  b_ += h * f_ext_;  // a few nonzeros, added into a dense vector: not worth a thread
}

void ThreadsStepper::element_terms(int e, const State& state, long long& fallbacks,
                                   Eigen::Matrix<double, 3, 4>& rhs,
                                   std::array<Eigen::Matrix3d, 10>& K) {
  const double h = scene_.dt, beta = scene_.damping.beta;
  const double c = h + beta;                  // b's df/dx term acts on (h + beta) v
  const double stiffness = h * beta + h * h;  // A = ... - (h beta + h^2) df/dx
  const Eigen::Vector4i& t = model_.tets[e];
  const ElementShape& shape = shapes_[e];
  Eigen::Matrix3d Ds, Dv;  // edge vectors of positions and velocities
  for (int i = 0; i < 3; ++i) {
    Ds.col(i) = state.x.segment<3>(3 * t[i + 1]) - state.x.segment<3>(3 * t[0]);
    Dv.col(i) = state.v.segment<3>(3 * t[i + 1]) - state.v.segment<3>(3 * t[0]);
  }
  Eigen::Quaterniond q = predicted_rotation(rotations_[e], previous_rotations_[e]);
  const Eigen::Matrix3d R = fast_polar_rotation(Ds * shape.Dm_inv, q, fallbacks);
  // The first step has no angular velocity to extrapolate: the next starts from R itself.
  previous_rotations_[e] = first_step_ ? q : rotations_[e];
  rotations_[e] = q;
  const Eigen::Matrix<double, 3, 4> r = rotated_gradients(R, shape.Dm_inv);

  // b_a += h f_a + h df/dx_a ((h + beta) v) without K0: both are -V P r_a with the linear
  // stress P = mu (G + G^T - 2 I) + lambda (tr G - 3) I of G = (F + (h + beta) dF/dt) R^T
  // (common/'s f_e = -R K0 (R^T x_e - X_e) and K0 summed over b, in the shape gradients).
  const Eigen::Matrix3d G = (Ds + c * Dv) * r.rightCols<3>().transpose();
  Eigen::Matrix3d P = shape.mu_volume * (G + G.transpose());
  P.diagonal().array() += shape.lambda_volume * (G.trace() - 3.0) - 2.0 * shape.mu_volume;
  rhs.noalias() = -h * P * r;

  // A += (h beta + h^2) K: ten blocks computed, sixteen written (K_ba = K_ab^T).
  stiffness_blocks(r, stiffness * shape.mu_volume, stiffness * shape.lambda_volume, K);
}

void ThreadsStepper::element_pass(const State& state) {
  if (element_parallelism_ == ElementParallelism::gather)
    element_pass_gather(state);
  else
    element_pass_colouring(state);
  first_step_ = false;
}

namespace {

// Where block (a, b) of an element comes from among the ten computed: pair p of
// kUpperPairs, transposed when a > b.
struct PairOf {
  int pair;
  bool transposed;
};
constexpr std::array<PairOf, 16> kPairOf = {{{0, false},
                                              {1, false},
                                              {2, false},
                                              {3, false},
                                              {1, true},
                                              {4, false},
                                              {5, false},
                                              {6, false},
                                              {2, true},
                                              {5, true},
                                              {7, false},
                                              {8, false},
                                              {3, true},
                                              {6, true},
                                              {8, true},
                                              {9, false}}};

}  // namespace

void ThreadsStepper::element_pass_gather(const State& state) {
  const int num_elements = static_cast<int>(model_.tets.size());
  long long fallbacks = 0;
  run_parallel([&] {
    // Every element on its own: its terms go to its own slots, nothing is shared. (An
    // integer sum is exact in any order: the one OpenMP reduction of the chapter.)
#pragma omp for schedule(static) reduction(+ : fallbacks)
    for (int e = 0; e < num_elements; ++e)
      element_terms(e, state, fallbacks, element_rhs_[e], element_K_[e]);
    // Every row sums its terms, in element order: b_i over the corners at node i, each
    // block over the element blocks that land on it.
#pragma omp for schedule(static)
    for (int c = 0; c < chunks_.count(); ++c) {
      for (int i = chunks_.start[c]; i < chunks_.start[c + 1]; ++i) {
        Eigen::Vector3d sum = b_.segment<3>(3 * i);
        for (int k = node_corner_start_[i]; k < node_corner_start_[i + 1]; ++k)
          sum += element_rhs_[node_corners_[k] / 4].col(node_corners_[k] % 4);
        b_.segment<3>(3 * i) = sum;
      }
      for (int k = A_.row_start[chunks_.start[c]]; k < A_.row_start[chunks_.start[c + 1]]; ++k) {
        Eigen::Matrix3d sum = A_.blocks[k];
        for (int t = block_term_start_[k]; t < block_term_start_[k + 1]; ++t) {
          const PairOf from = kPairOf[block_terms_[t] % 16];
          const Eigen::Matrix3d& K = element_K_[block_terms_[t] / 16][from.pair];
          if (from.transposed)
            sum += K.transpose();
          else
            sum += K;
        }
        A_.blocks[k] = sum;
      }
    }
  });
  last_step_fallbacks_ = fallbacks;
  total_fallbacks_ += fallbacks;
}

void ThreadsStepper::element_pass_colouring(const State& state) {
  long long fallbacks = 0;
  run_parallel([&] {
    Eigen::Matrix<double, 3, 4> rhs;
    std::array<Eigen::Matrix3d, 10> K;
    for (int colour = 0; colour < colours(); ++colour) {
      // The barrier at the end of each loop orders the colours: no two threads ever add
      // into the same node's blocks at the same time.
#pragma omp for schedule(static) reduction(+ : fallbacks)
      for (int k = colour_start_[colour]; k < colour_start_[colour + 1]; ++k) {
        const int group = colour_order_[k];
        const int last = std::min(static_cast<int>(model_.tets.size()), (group + 1) * kGroup);
        for (int e = group * kGroup; e < last; ++e) {
          element_terms(e, state, fallbacks, rhs, K);
          const Eigen::Vector4i& t = model_.tets[e];
          for (int a = 0; a < 4; ++a) b_.segment<3>(3 * t[a]) += rhs.col(a);
          const std::array<int, 16>& block = element_blocks_[e];
          for (std::size_t p = 0; p < kUpperPairs.size(); ++p) {
            const int a = kUpperPairs[p][0], b = kUpperPairs[p][1];
            A_.blocks[block[4 * a + b]] += K[p];
            if (a != b) A_.blocks[block[4 * b + a]] += K[p].transpose();
          }
        }
      }
    }
  });
  last_step_fallbacks_ = fallbacks;
  total_fallbacks_ += fallbacks;
}

void ThreadsStepper::apply_constraints(const State& state) {
  // z_i = (I - S_i)(v_target - v_i): the constrained part of the target velocity.
  z_.setZero(model_.dofs);
  for (const auto& c : scene_.constraints)
    z_.segment<3>(3 * c.node).noalias() = (Eigen::Matrix3d::Identity() - c.filter) *
                                          (c.target_velocity - state.v.segment<3>(3 * c.node));

  // S (b - A z): column i of A is row i transposed (A is symmetric), so the blocks a_ji
  // are the transposes of the blocks of row i, found through transpose_block_.
  filtered_b_ = b_;
  for (const auto& c : scene_.constraints) {
    const Eigen::Vector3d zi = z_.segment<3>(3 * c.node);
    if (zi.isZero(0.0)) continue;
    for (int k = A_.row_start[c.node]; k < A_.row_start[c.node + 1]; ++k)
      filtered_b_.segment<3>(3 * A_.column[k]).noalias() -= A_.blocks[transpose_block_[k]] * zi;
  }
  for (const auto& c : scene_.constraints)
    filtered_b_.segment<3>(3 * c.node) = c.filter * filtered_b_.segment<3>(3 * c.node);

  // S A S^T + I - S in place: a row of blocks is contiguous now, and the column blocks
  // a_ji are the transposes' positions of the row.
  for (const auto& c : scene_.constraints) {
    for (int k = A_.row_start[c.node]; k < A_.row_start[c.node + 1]; ++k) {
      A_.blocks[k] = c.filter * A_.blocks[k];
      Eigen::Matrix3d& a_ji = A_.blocks[transpose_block_[k]];
      a_ji = a_ji * c.filter;
    }
  }
  for (const auto& c : scene_.constraints)
    A_.blocks[diagonal_block_[c.node]] += Eigen::Matrix3d::Identity() - c.filter;
}

void ThreadsStepper::solve() {
  // Warm start: y_ still holds the previous step's answer; the solver filters it.
  const PcgResult result = pcg_.solve(A_, filtered_b_, settings_, y_);
  dv_ = y_;
  dv_ += z_;
  profile_.cg_iterations = result.iterations;
  profile_.relative_residual = result.relative_residual;
  profile_.converged = result.converged;
  report_if_not_converged(profile_, settings_, "09_threads", warned_not_converged_);
}

// ---- the solver ---------------------------------------------------------------------------

ParallelPcg::ParallelPcg(const BlockSparseMatrix& pattern, const std::vector<int>& diagonal_block,
                         const std::vector<NodeConstraint>& constraints)
    : chunks_(pattern), diagonal_block_(diagonal_block) {
  // The constraints of each chunk, in node order.
  constraints_ = constraints;  // a copy, sorted by node: no reference into a scene
  std::stable_sort(constraints_.begin(), constraints_.end(),
                   [](const NodeConstraint& a, const NodeConstraint& b) { return a.node < b.node; });
  constraint_start_.assign(chunks_.count() + 1, 0);
  for (int c = 0, k = 0; c < chunks_.count(); ++c) {
    while (k < static_cast<int>(constraints_.size()) &&
           constraints_[k].node < chunks_.start[c + 1])
      ++k;
    constraint_start_[c + 1] = k;
  }
  inverse_diagonal_.resize(pattern.block_rows());
  for (auto* partial : {&partial_bb_, &partial_pq_, &partial_rr_, &partial_rs_})
    partial->assign(chunks_.count(), 0.0);
}

PcgResult ParallelPcg::solve(const BlockSparseMatrix& A, const Eigen::VectorXd& b,
                             const SolverSettings& settings, Eigen::VectorXd& y) {
  const Eigen::Index n = b.size();
  // Same sizes every step: these resizes allocate on the first solve only.
  r_.resize(n);
  s_.resize(n);
  p_.resize(n);
  q_.resize(n);
  const int chunks = chunks_.count();
  const std::vector<int>& start = chunks_.start;
  // v_i <- S_i v_i on the constrained nodes of chunk c: the PPCG projection onto the free
  // subspace.
  const auto filter = [this](int c, Eigen::VectorXd& v) {
    for (int k = constraint_start_[c]; k < constraint_start_[c + 1]; ++k) {
      const NodeConstraint& constraint = constraints_[k];
      v.segment<3>(3 * constraint.node) = constraint.filter * v.segment<3>(3 * constraint.node);
    }
  };
  // s_i = D_i^-1 r_i with D_i the 3x3 diagonal block: block Jacobi.
  const auto precondition = [this](int first, int last, const Eigen::VectorXd& r,
                                   Eigen::VectorXd& s) {
    for (int i = first; i < last; ++i)
      s.segment<3>(3 * i).noalias() = inverse_diagonal_[i] * r.segment<3>(3 * i);
  };

  PcgResult result;
  run_parallel([&] {
    // Everything below runs on every thread; a `#pragma omp for` shares its chunks out and
    // ends with a barrier. The scalars (norms, rho, the step) are each thread's own copy,
    // added up from the same partial sums in the same order: equal on every thread, so
    // every thread takes the same branches.

    // The block-Jacobi inverses (the diagonal blocks of the filtered matrix are symmetric
    // positive definite: a fixed-size 3x3 inverse each), the filtered guess, ||b||^2.
#pragma omp for schedule(static)
    for (int c = 0; c < chunks; ++c) {
      for (int i = start[c]; i < start[c + 1]; ++i)
        inverse_diagonal_[i] = A.blocks[diagonal_block_[i]].inverse();
      filter(c, y);
      partial_bb_[c] = b.segment(3 * start[c], 3 * (start[c + 1] - start[c])).squaredNorm();
    }
    const double rhs_norm2 = sum_in_order(partial_bb_);
    const double threshold = std::max(settings.tolerance * settings.tolerance * rhs_norm2,
                                      std::numeric_limits<double>::min());
    if (rhs_norm2 == 0.0) {  // as Eigen: the solution of A y = 0 is 0
#pragma omp for schedule(static)
      for (int c = 0; c < chunks; ++c)
        y.segment(3 * start[c], 3 * (start[c + 1] - start[c])).setZero();
#pragma omp master
      result.converged = true;
      return;
    }

    // r = S (b - A y), p = S D^-1 r, with ||r||^2 and rho = r . p, chunk by chunk.
#pragma omp for schedule(static)
    for (int c = 0; c < chunks; ++c) {
      const int first = start[c], size = 3 * (start[c + 1] - start[c]);
      A.multiply_rows(y, q_, start[c], start[c + 1]);
      r_.segment(3 * first, size) = b.segment(3 * first, size) - q_.segment(3 * first, size);
      filter(c, r_);
      precondition(start[c], start[c + 1], r_, p_);
      filter(c, p_);
      partial_rr_[c] = r_.segment(3 * first, size).squaredNorm();
      partial_rs_[c] = r_.segment(3 * first, size).dot(p_.segment(3 * first, size));
    }
    double residual_norm2 = sum_in_order(partial_rr_);
    double rho = sum_in_order(partial_rs_);
    int iterations = 0;
    while (residual_norm2 >= threshold && iterations < settings.max_iterations) {
      // q = A p and p . q: the SpMV reads p of the neighbouring rows, hence the barrier
      // before it (at the end of the previous update of p).
#pragma omp for schedule(static)
      for (int c = 0; c < chunks; ++c) {
        const int first = start[c], size = 3 * (start[c + 1] - start[c]);
        A.multiply_rows(p_, q_, start[c], start[c + 1]);
        partial_pq_[c] = p_.segment(3 * first, size).dot(q_.segment(3 * first, size));
      }
      const double step = rho / sum_in_order(partial_pq_);
      // An overflowing system (an absurd E) overflows here: stop before y does, with a
      // residual that says so, rather than iterate on NaN up to the cap. Every thread sees
      // the same step, so every thread stops.
      if (!std::isfinite(step)) {
        residual_norm2 = std::numeric_limits<double>::quiet_NaN();
        break;
      }
      // Every vector operation of the iteration that needs no neighbour, on one chunk at a
      // time while it sits in L1: y += step p, r -= step q, r filtered, s = S D^-1 r,
      // ||r||^2 and r . s. Each is an Eigen expression on the chunk's segment, so it keeps
      // the SIMD of the whole-vector operations of the chapters before.
#pragma omp for schedule(static)
      for (int c = 0; c < chunks; ++c) {
        const int first = start[c], size = 3 * (start[c + 1] - start[c]);
        y.segment(3 * first, size) += step * p_.segment(3 * first, size);
        r_.segment(3 * first, size) -= step * q_.segment(3 * first, size);
        filter(c, r_);
        precondition(start[c], start[c + 1], r_, s_);
        filter(c, s_);
        partial_rr_[c] = r_.segment(3 * first, size).squaredNorm();
        partial_rs_[c] = r_.segment(3 * first, size).dot(s_.segment(3 * first, size));
      }
      ++iterations;
      residual_norm2 = sum_in_order(partial_rr_);
      if (residual_norm2 < threshold) break;
      const double rho_old = rho;
      rho = sum_in_order(partial_rs_);
      const double beta = rho / rho_old;
#pragma omp for schedule(static)
      for (int c = 0; c < chunks; ++c) {
        const int first = start[c], size = 3 * (start[c + 1] - start[c]);
        p_.segment(3 * first, size) = s_.segment(3 * first, size) + beta * p_.segment(3 * first, size);
      }
    }
#pragma omp master
    {
      result.iterations = iterations;
      result.relative_residual = std::sqrt(residual_norm2 / rhs_norm2);
      result.converged = residual_norm2 < threshold;
    }
  });
  return result;
}

}  // namespace fem::ch09
