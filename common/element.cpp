#include "common/element.hpp"

#include <Eigen/LU>
#include <Eigen/SVD>
#include <cmath>

namespace fem {

Lame lame_from_young_poisson(double E, double nu) {
  return {E / (2.0 * (1.0 + nu)), E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))};
}

Eigen::Matrix<double, 3, 4> shape_gradients(const Eigen::Matrix3d& Dm_inv) {
  // F = Ds Dm^-1 = sum_{i=1..3} (x_i - x_0) row_i(Dm^-1): g_i is row i-1 of Dm^-1.
  Eigen::Matrix<double, 3, 4> g;
  g.rightCols<3>() = Dm_inv.transpose();
  g.col(0) = -g.rightCols<3>().rowwise().sum();
  return g;
}

ElementRest make_element_rest(const Vector12d& X, const Lame& lame) {
  ElementRest rest;
  Eigen::Matrix3d Dm;
  for (int i = 0; i < 3; ++i) Dm.col(i) = X.segment<3>(3 * (i + 1)) - X.segment<3>(0);
  rest.Dm_inv = Dm.inverse();
  rest.volume = std::abs(Dm.determinant()) / 6.0;
  rest.X = X;

  // K_ab = V [ mu (g_a . g_b) I + mu g_b g_a^T + lambda g_a g_b^T ]: the Hessian of
  // V (mu eps:eps + lambda/2 tr(eps)^2) with eps = sym(grad u).
  const Eigen::Matrix<double, 3, 4> g = shape_gradients(rest.Dm_inv);
  for (int a = 0; a < 4; ++a) {
    for (int b = 0; b < 4; ++b) {
      const Eigen::Vector3d ga = g.col(a), gb = g.col(b);
      rest.K0.block<3, 3>(3 * a, 3 * b) =
          rest.volume * (lame.mu * ga.dot(gb) * Eigen::Matrix3d::Identity() +
                         lame.mu * gb * ga.transpose() + lame.lambda * ga * gb.transpose());
    }
  }
  return rest;
}

Eigen::Matrix3d deformation_gradient(const ElementRest& rest, const Vector12d& x) {
  Eigen::Matrix3d Ds;
  for (int i = 0; i < 3; ++i) Ds.col(i) = x.segment<3>(3 * (i + 1)) - x.segment<3>(0);
  return Ds * rest.Dm_inv;
}

Eigen::Matrix3d polar_rotation(const Eigen::Matrix3d& F) {
  // A fixed-size JacobiSVD allocates nothing; singular values come sorted, largest first.
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(F, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d U = svd.matrixU();
  const Eigen::Matrix3d V = svd.matrixV();
  if ((U * V.transpose()).determinant() < 0.0) U.col(2) = -U.col(2);
  return U * V.transpose();
}

Vector12d element_force(const ElementRest& rest, const Eigen::Matrix3d& R, const Vector12d& x) {
  Vector12d u;  // R^T x_e - X_e: the displacement seen in the element's unrotated frame
  for (int a = 0; a < 4; ++a) u.segment<3>(3 * a) = R.transpose() * x.segment<3>(3 * a);
  u -= rest.X;
  const Vector12d k0u = rest.K0 * u;
  Vector12d f;
  for (int a = 0; a < 4; ++a) f.segment<3>(3 * a) = -R * k0u.segment<3>(3 * a);
  return f;
}

double element_energy(const ElementRest& rest, const Lame& lame, const Vector12d& x) {
  const Eigen::Matrix3d F = deformation_gradient(rest, x);
  const Eigen::Matrix3d R = polar_rotation(F);
  const double tr = (R.transpose() * F).trace() - 3.0;
  return rest.volume * (lame.mu * (F - R).squaredNorm() + 0.5 * lame.lambda * tr * tr);
}

Matrix12d element_dfdx(const ElementRest& rest, const Eigen::Matrix3d& R) {
  Matrix12d K;
  for (int a = 0; a < 4; ++a)
    for (int b = 0; b < 4; ++b) K.block<3, 3>(3 * a, 3 * b) = dfdx_block(rest, R, a, b);
  return K;
}

}  // namespace fem
