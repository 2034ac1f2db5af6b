// Chapter 08's element kernels: Newton's polar rotation, the closed-form blocks, and the
// fused terms of one element.
#include "chapters/08_element_kernels/element_kernels.hpp"

#include <cmath>

namespace fem::ch08 {

ElementShape make_element_shape(const ElementRest& rest, const Lame& lame) {
  return {rest.Dm_inv, rest.volume * lame.mu, rest.volume * lame.lambda};
}

namespace {

using namespace newton;

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
    if (!solve_positive_definite(
            H, axial, kMinRelativeHessianDet * q2 * q2 * q2 * scale2 * std::sqrt(scale2), w))
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
                                    long long& fallbacks, int* iterations) {
  Eigen::Quaterniond start = q;
  const int k = newton_polar_rotation(F, start);
  if (iterations) *iterations = k > 0 ? k : 0;
  if (k > 0) {
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

void stiffness_blocks(const Eigen::Matrix<double, 3, 4>& r, double mu_volume, double lambda_volume,
                      std::array<Eigen::Matrix3d, 10>& K) {
  for (std::size_t p = 0; p < kUpperPairs.size(); ++p) {
    const auto ra = r.col(kUpperPairs[p][0]), rb = r.col(kUpperPairs[p][1]);
    // One outer product serves both rank-one terms: r_b r_a^T and its transpose.
    const Eigen::Matrix3d outer = rb * ra.transpose();
    K[p] = mu_volume * outer + lambda_volume * outer.transpose();
    K[p].diagonal().array() += mu_volume * ra.dot(rb);
  }
}

FusedElements::FusedElements(const Model& model, const Scene& scene)
    : h_(scene.dt),
      velocity_scale_(scene.dt + scene.damping.beta),
      stiffness_(scene.dt * scene.damping.beta + scene.dt * scene.dt) {
  const Lame lame =
      lame_from_young_poisson(scene.material.youngs_modulus, scene.material.poisson_ratio);
  shapes_.reserve(model.tets.size());
  for (const ElementRest& rest : model.rest) shapes_.push_back(make_element_shape(rest, lame));
  // The rest shape's, as a start: a stepper created on a deformed body (the viewer switching
  // chapters) starts cold, and Newton or the SVD fallback finds the rotations.
  rotations_.assign(model.tets.size(), Eigen::Quaterniond::Identity());
  previous_rotations_ = rotations_;
}

void FusedElements::terms(int e, const Eigen::Vector4i& t, const State& state, long long& fallbacks,
                          ElementTerms& out) {
  const ElementShape& shape = shapes_[e];
  Eigen::Matrix3d Ds, Dv;  // edge vectors of positions and velocities
  for (int i = 0; i < 3; ++i) {
    Ds.col(i) = state.x.segment<3>(3 * t[i + 1]) - state.x.segment<3>(3 * t[0]);
    Dv.col(i) = state.v.segment<3>(3 * t[i + 1]) - state.v.segment<3>(3 * t[0]);
  }
  Eigen::Quaterniond q = predicted_rotation(rotations_[e], previous_rotations_[e]);
  int iterations = 0;
  const Eigen::Matrix3d R = fast_polar_rotation(Ds * shape.Dm_inv, q, fallbacks, &iterations);
  iterations_.add(iterations);
  // The first step has no angular velocity to extrapolate: the next starts from R itself.
  previous_rotations_[e] = first_step_ ? q : rotations_[e];
  rotations_[e] = q;
  const Eigen::Matrix<double, 3, 4> r = rotated_gradients(R, shape.Dm_inv);

  // b_a += h f_a + h df/dx_a ((h + beta) v) without K0: both are -V P r_a with the linear
  // stress P = mu (G + G^T - 2 I) + lambda (tr G - 3) I of G = (F + (h + beta) dF/dt) R^T
  // (common/'s f_e = -R K0 (R^T x_e - X_e) and K0 summed over b, in the shape gradients).
  const Eigen::Matrix3d G = (Ds + velocity_scale_ * Dv) * r.rightCols<3>().transpose();
  Eigen::Matrix3d P = shape.mu_volume * (G + G.transpose());
  P.diagonal().array() += shape.lambda_volume * (G.trace() - 3.0) - 2.0 * shape.mu_volume;
  out.rhs.noalias() = -h_ * P * r;

  // A += (h beta + h^2) K.
  stiffness_blocks(r, stiffness_ * shape.mu_volume, stiffness_ * shape.lambda_volume, out.K);
}

void FusedElements::end_pass(long long fallbacks) {
  first_step_ = false;
  last_step_fallbacks_ = fallbacks;
  total_fallbacks_ += fallbacks;
  total_rotations_ += static_cast<long long>(shapes_.size());
}

void scatter(const Eigen::Vector4i& t, const std::array<int, 16>& blocks, const ElementTerms& terms,
             ch07::BlockSparseMatrix& A, Eigen::VectorXd& b) {
  for (int a = 0; a < 4; ++a) b.segment<3>(3 * t[a]) += terms.rhs.col(a);
  for (std::size_t p = 0; p < kUpperPairs.size(); ++p) {
    const int a = kUpperPairs[p][0], c = kUpperPairs[p][1];
    A.blocks[blocks[4 * a + c]] += terms.K[p];
    if (a != c) A.blocks[blocks[4 * c + a]] += terms.K[p].transpose();
  }
}

}  // namespace fem::ch08
