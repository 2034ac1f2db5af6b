// The corotated element kernels against finite differences.
#include <Eigen/Geometry>
#include <cmath>

#include "catch2_compat.hpp"
#include "common/element.hpp"

using namespace fem;

namespace {

const Lame kLame = lame_from_young_poisson(1e5, 0.3);

Vector12d rest_positions() {
  Vector12d X;
  X << 0.1, 0.0, 0.0, 1.0, 0.1, 0.0, 0.0, 1.1, 0.1, 0.2, 0.1, 0.9;
  return X;
}

// x = Q (X + D X) + t: a deformation D, then a rigid rotation Q and translation t.
Vector12d transform(const Vector12d& X, const Eigen::Matrix3d& Q, const Eigen::Matrix3d& D,
                    const Eigen::Vector3d& t) {
  Vector12d x;
  for (int a = 0; a < 4; ++a) {
    const Eigen::Vector3d Xa = X.segment<3>(3 * a);
    x.segment<3>(3 * a) = Q * (Xa + D * Xa) + t;
  }
  return x;
}

Eigen::Matrix3d some_rotation() {
  return Eigen::AngleAxisd(0.7, Eigen::Vector3d(1.0, 2.0, -0.5).normalized()).toRotationMatrix();
}

Eigen::Matrix3d some_deformation(double strain) {
  Eigen::Matrix3d D;
  D << 0.3, -0.2, 0.5, 0.1, -0.4, 0.2, 0.6, 0.1, 0.2;
  return strain * D;
}

Vector12d force_at(const ElementRest& rest, const Vector12d& x) {
  return element_force(rest, polar_rotation(deformation_gradient(rest, x)), x);
}

// Central-difference gradient of the energy.
Vector12d fd_gradient(const ElementRest& rest, const Vector12d& x, double eps) {
  Vector12d g;
  for (int i = 0; i < 12; ++i) {
    Vector12d xp = x, xm = x;
    xp[i] += eps;
    xm[i] -= eps;
    g[i] = (element_energy(rest, kLame, xp) - element_energy(rest, kLame, xm)) / (2.0 * eps);
  }
  return g;
}

// Central-difference Jacobian of the force, the rotation recomputed at each point.
Matrix12d fd_jacobian(const ElementRest& rest, const Vector12d& x, double eps) {
  Matrix12d J;
  for (int i = 0; i < 12; ++i) {
    Vector12d xp = x, xm = x;
    xp[i] += eps;
    xm[i] -= eps;
    J.col(i) = (force_at(rest, xp) - force_at(rest, xm)) / (2.0 * eps);
  }
  return J;
}

}  // namespace

TEST_CASE("rest stiffness K0 is symmetric and annihilates rigid motions", "[element]") {
  const ElementRest rest = make_element_rest(rest_positions(), kLame);
  CHECK((rest.K0 - rest.K0.transpose()).norm() <= 1e-12 * rest.K0.norm());
  Vector12d translation, rotation;
  const Eigen::Vector3d w(0.3, -1.0, 0.4);
  for (int a = 0; a < 4; ++a) {
    translation.segment<3>(3 * a) = Eigen::Vector3d(1.0, -2.0, 0.5);
    rotation.segment<3>(3 * a) = w.cross(Eigen::Vector3d(rest.X.segment<3>(3 * a)));
  }
  CHECK((rest.K0 * translation).norm() <= 1e-10 * rest.K0.norm());
  CHECK((rest.K0 * rotation).norm() <= 1e-10 * rest.K0.norm());
}

TEST_CASE("element force is minus the energy gradient (finite differences)", "[element]") {
  const ElementRest rest = make_element_rest(rest_positions(), kLame);
  const Vector12d x =
      transform(rest.X, some_rotation(), some_deformation(0.2), Eigen::Vector3d(0.5, -0.3, 2.0));
  const Vector12d f = force_at(rest, x);
  REQUIRE(f.norm() > 0.0);
  double previous = INFINITY;
  double best = INFINITY;
  for (const double eps : {1e-2, 1e-3, 1e-4}) {
    const double error = (f + fd_gradient(rest, x, eps)).norm() / f.norm();
    CHECK(error < previous);  // the central difference error shrinks as eps^2
    previous = error;
    best = std::min(best, error);
  }
  CHECK(best < 1e-7);
}

TEST_CASE("warped stiffness -R K0 R^T is the force Jacobian of a rotated rest shape", "[element]") {
  const ElementRest rest = make_element_rest(rest_positions(), kLame);
  const Vector12d x =
      transform(rest.X, some_rotation(), Eigen::Matrix3d::Zero(), Eigen::Vector3d(1.0, 2.0, 3.0));
  const Eigen::Matrix3d R = polar_rotation(deformation_gradient(rest, x));
  const Matrix12d K = element_dfdx(rest, R);
  double previous = INFINITY;
  for (const double eps : {1e-3, 1e-4, 1e-5}) {
    const double error = (fd_jacobian(rest, x, eps) - K).norm() / K.norm();
    CHECK(error < std::max(previous, 1e-8));
    previous = error;
  }
  CHECK(previous < 1e-7);
}

TEST_CASE("warped stiffness leaves out dR/dx: its error grows linearly with the strain",
          "[element]") {
  // Away from the rest shape, -R K0 R^T drops the term (dR/dx) K0 (R^T x - X). That
  // term is proportional to the strain: ten times the strain, ten times the error.
  const ElementRest rest = make_element_rest(rest_positions(), kLame);
  const auto relative_error = [&](double strain) {
    const Vector12d x =
        transform(rest.X, some_rotation(), some_deformation(strain), Eigen::Vector3d::Zero());
    const Matrix12d K = element_dfdx(rest, polar_rotation(deformation_gradient(rest, x)));
    return (fd_jacobian(rest, x, 1e-6) - K).norm() / K.norm();
  };
  const double small = relative_error(1e-3), large = relative_error(1e-2);
  CHECK(small < 1e-2);
  CHECK(large / small == Approx(10.0).epsilon(0.1));
}

TEST_CASE("rigid rotation plus translation gives zero force", "[element]") {
  const ElementRest rest = make_element_rest(rest_positions(), kLame);
  const Vector12d x =
      transform(rest.X, some_rotation(), Eigen::Matrix3d::Zero(), Eigen::Vector3d(-4.0, 1.0, 7.0));
  const Vector12d stretched =
      transform(rest.X, some_rotation(), some_deformation(0.01), Eigen::Vector3d::Zero());
  const double scale = force_at(rest, stretched).norm();  // the force of a 1% strain
  CHECK(force_at(rest, x).norm() < 1e-9 * scale);
}

TEST_CASE("polar rotation is a proper rotation, also for an inverted element", "[element]") {
  Eigen::Matrix3d F = some_rotation() * (Eigen::Matrix3d::Identity() + some_deformation(0.3));
  F.col(2) = -F.col(2);  // det F < 0
  REQUIRE(F.determinant() < 0.0);
  const Eigen::Matrix3d R = polar_rotation(F);
  CHECK(R.determinant() == Approx(1.0).epsilon(1e-12));
  CHECK((R.transpose() * R - Eigen::Matrix3d::Identity()).norm() < 1e-12);
  const Eigen::Matrix3d S = R.transpose() * F;  // the stretch is symmetric
  CHECK((S - S.transpose()).norm() < 1e-12 * S.norm());
}

TEST_CASE("polar rotation of an inverted element: the flip is on the smallest singular value",
          "[element]") {
  // F = R0 diag(s) with one negative entry. The corotational convention (Irving et al.
  // 2004) makes det R = +1 by flipping the direction of the SMALLEST singular value, the one
  // an element crushed through a face has lost: the rotation is then R0 when that direction
  // is the inverted one, and R0 diag(-1, 1, -1) when the largest is. Flipping any other
  // direction also gives det 1 and an orthogonal R, so only the known answer tests it.
  const Eigen::Matrix3d R0 = some_rotation();
  const Eigen::Matrix3d crushed = R0 * Eigen::Vector3d(2.0, 1.5, -0.5).asDiagonal();
  CHECK((polar_rotation(crushed) - R0).norm() < 1e-12);
  const Eigen::Matrix3d flipped_long_axis = R0 * Eigen::Vector3d(-2.0, 1.5, 0.5).asDiagonal();
  const Eigen::Matrix3d expected = R0 * Eigen::Vector3d(-1.0, 1.0, -1.0).asDiagonal();
  CHECK((polar_rotation(flipped_long_axis) - expected).norm() < 1e-12);
}

TEST_CASE("an inverted element gets a finite force that pushes it back", "[element]") {
  const ElementRest rest = make_element_rest(rest_positions(), kLame);
  // Push node 3 through the face (0, 1, 2), to half its height on the other side. (Not
  // to the mirror image: F would be a reflection, all singular values 1, and the
  // flipped direction of the polar decomposition would be arbitrary.)
  const Eigen::Vector3d x0 = rest.X.segment<3>(0), x1 = rest.X.segment<3>(3),
                        x2 = rest.X.segment<3>(6), x3 = rest.X.segment<3>(9);
  const Eigen::Vector3d n = (x1 - x0).cross(x2 - x0).normalized();  // towards x3
  Vector12d x = rest.X;
  x.segment<3>(9) = x3 - 1.5 * n.dot(x3 - x0) * n;
  REQUIRE(deformation_gradient(rest, x).determinant() < 0.0);
  const Vector12d f = force_at(rest, x);
  REQUIRE(f.allFinite());
  CHECK(f.segment<3>(9).dot(n) > 0.0);  // node 3 is pushed back towards its rest side
}
