// Chapter 08: one linearized backward Euler step (Baraff & Witkin 1998),
//   A dv = b,  A = M - h df/dv - h^2 df/dx,  b = h (f + h df/dx v),
// with velocity constraints by the filter S of the PPCG method (Tamstorf et al. 2015):
//   (S A S^T + I - S) y = S (b - A z),  dv = y + z.
// Chapter 08 changes the element loop: rotations by a warm-started Newton iteration instead
// of an SVD, the blocks of df/dx in closed form instead of R K0 R^T with a stored K0, and
// one pass over the elements that writes into A and b directly, with no df/dx matrix.
#include "chapters/08_element_kernels/stepper.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>

namespace fem::ch08 {

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

void BlockSparseMatrix::multiply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const {
  const int n = block_rows();
  for (int i = 0; i < n; ++i) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();  // in registers: y_i is written once
    for (int k = row_start[i]; k < row_start[i + 1]; ++k)
      sum.noalias() += blocks[k] * x.segment<3>(3 * column[k]);
    y.segment<3>(3 * i) = sum;
  }
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

ElementKernelsStepper::ElementKernelsStepper(const Scene& scene, const SolverSettings& settings)
    : Stepper(scene), scene_(scene), model_(scene), settings_(settings) {
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
  b_.resize(n);
  y_.setZero(n);
}

void ElementKernelsStepper::step(State& state) {
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

void ElementKernelsStepper::start_system(const State& state) {
  const double h = scene_.dt, alpha = scene_.damping.alpha;
  // What the elements do not touch: A = (1 + h alpha) M, b = h (f_gravity - alpha M v + f_ext).
  for (auto& block : A_.blocks) block.setZero();
  const double mass_factor = 1.0 + h * alpha;
  for (int i = 0; i < model_.num_nodes; ++i)
    A_.blocks[diagonal_block_[i]].diagonal() = mass_factor * model_.lumped_mass.segment<3>(3 * i);
  b_.noalias() = h * model_.gravity_force - (h * alpha) * model_.lumped_mass.cwiseProduct(state.v);
  b_ += h * f_ext_;  // a sparse vector added into a dense one: no temporary
}

void ElementKernelsStepper::element_pass(const State& state) {
  const double h = scene_.dt, beta = scene_.damping.beta;
  const double c = h + beta;                  // b's df/dx term acts on (h + beta) v
  const double stiffness = h * beta + h * h;  // A = ... - (h beta + h^2) df/dx
  long long fallbacks = 0;
  std::array<Eigen::Matrix3d, 10> K;
  for (std::size_t e = 0; e < model_.tets.size(); ++e) {
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
    const Eigen::Matrix<double, 3, 4> Pr = -h * P * r;
    for (int a = 0; a < 4; ++a) b_.segment<3>(3 * t[a]) += Pr.col(a);

    // A += (h beta + h^2) K: ten blocks computed, sixteen written (K_ba = K_ab^T).
    stiffness_blocks(r, stiffness * shape.mu_volume, stiffness * shape.lambda_volume, K);
    const std::array<int, 16>& block = element_blocks_[e];
    for (std::size_t p = 0; p < kUpperPairs.size(); ++p) {
      const int a = kUpperPairs[p][0], b = kUpperPairs[p][1];
      A_.blocks[block[4 * a + b]] += K[p];
      if (a != b) A_.blocks[block[4 * b + a]] += K[p].transpose();
    }
  }
  first_step_ = false;
  last_step_fallbacks_ = fallbacks;
  total_fallbacks_ += fallbacks;
}

void ElementKernelsStepper::apply_constraints(const State& state) {
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

void ElementKernelsStepper::solve() {
  // Warm start: y_ still holds the previous step's answer; pcg_solve filters it.
  const PcgResult result =
      pcg_solve(A_, diagonal_block_, filtered_b_, scene_.constraints, settings_, pcg_, y_);
  dv_ = y_;
  dv_ += z_;
  profile_.cg_iterations = result.iterations;
  profile_.relative_residual = result.relative_residual;
  profile_.converged = result.converged;
  report_if_not_converged(profile_, settings_, "08_element_kernels", warned_not_converged_);
}

// ---- the solver ---------------------------------------------------------------------------

namespace {

// v_i <- S_i v_i on the constrained nodes: the PPCG projection onto the free subspace.
void filter(const std::vector<NodeConstraint>& constraints, Eigen::VectorXd& v) {
  for (const auto& c : constraints) v.segment<3>(3 * c.node) = c.filter * v.segment<3>(3 * c.node);
}

// s_i = D_i^-1 r_i with D_i the 3x3 diagonal block: block Jacobi.
void precondition(const std::vector<Eigen::Matrix3d>& inverse_diagonal, const Eigen::VectorXd& r,
                  Eigen::VectorXd& s) {
  for (std::size_t i = 0; i < inverse_diagonal.size(); ++i)
    s.segment<3>(3 * i).noalias() = inverse_diagonal[i] * r.segment<3>(3 * i);
}

}  // namespace

PcgResult pcg_solve(const BlockSparseMatrix& A, const std::vector<int>& diagonal_block,
                    const Eigen::VectorXd& b, const std::vector<NodeConstraint>& constraints,
                    const SolverSettings& settings, PcgWorkspace& work, Eigen::VectorXd& y) {
  const Eigen::Index n = b.size();
  auto& [r, s, p, q, inverse_diagonal] = work;
  // Same sizes every step: these resizes allocate on the first solve only.
  r.resize(n);
  s.resize(n);
  p.resize(n);
  q.resize(n);
  inverse_diagonal.resize(diagonal_block.size());
  // The diagonal blocks of the filtered matrix are symmetric positive definite (a fixed
  // node's is the identity), so each has an inverse: a fixed-size 3x3 inverse, no search.
  for (std::size_t i = 0; i < diagonal_block.size(); ++i)
    inverse_diagonal[i] = A.blocks[diagonal_block[i]].inverse();

  PcgResult result;
  const double rhs_norm2 = b.squaredNorm();
  if (rhs_norm2 == 0.0) {  // as Eigen: the solution of A y = 0 is 0
    y.setZero();
    result.converged = true;
    return result;
  }
  filter(constraints, y);
  A.multiply(y, q);
  r = b - q;
  filter(constraints, r);
  const double threshold = std::max(settings.tolerance * settings.tolerance * rhs_norm2,
                                    std::numeric_limits<double>::min());
  double residual_norm2 = r.squaredNorm();
  if (residual_norm2 >= threshold) {
    precondition(inverse_diagonal, r, p);
    filter(constraints, p);
    double rho = r.dot(p);
    while (result.iterations < settings.max_iterations) {
      A.multiply(p, q);
      const double step = rho / p.dot(q);
      // An overflowing system (an absurd E) stays finite through the closed-form kernels,
      // where K0 overflowed at once; it overflows here instead. Stop before y does, with a
      // residual that says so, rather than iterate on NaN up to the cap.
      if (!std::isfinite(step)) {
        residual_norm2 = std::numeric_limits<double>::quiet_NaN();
        break;
      }
      y += step * p;
      r -= step * q;
      filter(constraints, r);
      ++result.iterations;
      residual_norm2 = r.squaredNorm();
      if (residual_norm2 < threshold) break;
      precondition(inverse_diagonal, r, s);
      filter(constraints, s);
      const double rho_old = rho;
      rho = r.dot(s);
      p = s + (rho / rho_old) * p;
    }
  }
  result.relative_residual = std::sqrt(residual_norm2 / rhs_norm2);
  result.converged = residual_norm2 < threshold;
  return result;
}

}  // namespace fem::ch08
