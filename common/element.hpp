// Corotated linear elasticity on one linear tetrahedron (stiffness warping,
// Mueller & Gross 2004). Everything here is per element and fixed-size: these
// kernels are shared by every chapter, which differ only in how the global
// system is assembled, constrained and solved.
#pragma once

#include <Eigen/Core>

namespace fem {

using Matrix12d = Eigen::Matrix<double, 12, 12>;
using Vector12d = Eigen::Matrix<double, 12, 1>;

// Lame parameters from Young's modulus E and Poisson's ratio nu.
struct Lame {
  double mu;
  double lambda;
};
Lame lame_from_young_poisson(double youngs_modulus, double poisson_ratio);

// What an element needs from its rest shape X_e = (X0, X1, X2, X3).
struct ElementRest {
  Eigen::Matrix3d Dm_inv;  // inverse of Dm = [X1-X0, X2-X0, X3-X0]
  double volume;           // rest volume |det Dm| / 6
  Matrix12d K0;            // rest stiffness, 4x4 blocks of 3x3: f_e = -R K0 (R^T x_e - X_e)
  Vector12d X;             // rest positions, stacked
};

// Dm^-1, volume and K0 for a positively oriented rest tetrahedron (det Dm > 0).
ElementRest make_element_rest(const Vector12d& X, const Lame& lame);

// Shape function gradients g_a (columns) of the four nodes: F = sum_a x_a g_a^T.
Eigen::Matrix<double, 3, 4> shape_gradients(const Eigen::Matrix3d& Dm_inv);

// Deformation gradient F = Ds Dm^-1 of the stacked element positions x.
Eigen::Matrix3d deformation_gradient(const ElementRest& rest, const Vector12d& x);

// Rotation R of the polar decomposition F = R S with det R = +1, also when F is
// inverted (det F < 0): the singular direction of the smallest singular value is
// flipped so that R stays a rotation and S a symmetric (indefinite) stretch.
Eigen::Matrix3d polar_rotation(const Eigen::Matrix3d& F);

// Elastic force on the element's nodes: f_e = -R K0 (R^T x_e - X_e).
Vector12d element_force(const ElementRest& rest, const Eigen::Matrix3d& R, const Vector12d& x);

// Corotated energy whose exact negative gradient is element_force:
// V * (mu |F - R|^2 + lambda/2 tr(R^T F - I)^2). Used by the finite-difference tests.
double element_energy(const ElementRest& rest, const Lame& lame, const Vector12d& x);

// Block (a, b) of the warped stiffness df/dx_e = -R K0 R^T (a, b in 0..3).
inline Eigen::Matrix3d dfdx_block(const ElementRest& rest, const Eigen::Matrix3d& R, int a, int b) {
  return -R * rest.K0.block<3, 3>(3 * a, 3 * b) * R.transpose();
}

// The whole 12x12 element df/dx = -R K0 R^T.
Matrix12d element_dfdx(const ElementRest& rest, const Eigen::Matrix3d& R);

}  // namespace fem
