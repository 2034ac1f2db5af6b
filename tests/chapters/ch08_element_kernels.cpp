// Chapter 08: the fast rotation is common/'s SVD rotation, the closed-form blocks are
// common/'s dfdx_block, the fused pass builds chapter 07's system, and the stepper still
// matches chapter 01 without allocating.
#include <Eigen/SVD>
#include <random>

#include "catch2_compat.hpp"
#include "chapters/07_block_sparse/stepper.hpp"
#include "chapters/08_element_kernels/stepper.hpp"
#include "support.hpp"

using namespace fem;

namespace {

// Deformation gradients F = U diag(s) V^T with random rotations U, V and given singular
// values: the SVD rotation is then known to be U diag(1, 1, sign) V^T.
Eigen::Matrix3d random_rotation(std::mt19937& rng) {
  std::normal_distribution<double> normal;
  Eigen::Quaterniond q(normal(rng), normal(rng), normal(rng), normal(rng));
  return q.normalized().toRotationMatrix();
}

Eigen::Matrix3d gradient_with(std::mt19937& rng, const Eigen::Vector3d& singular_values) {
  return random_rotation(rng) * singular_values.asDiagonal() * random_rotation(rng).transpose();
}

// A rotation at most `angle` radians from R.
Eigen::Quaterniond near(const Eigen::Matrix3d& R, double angle, std::mt19937& rng) {
  std::normal_distribution<double> normal;
  const Eigen::Vector3d axis = Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
  return Eigen::Quaterniond(R * Eigen::AngleAxisd(angle, axis).toRotationMatrix());
}

// The tolerance of the rotation comparisons: Newton stops when its step is below 1e-8 rad,
// which leaves an error of about 1e-16 after quadratic convergence; the SVD's own rounding
// is of the same order. 1e-12 leaves room for the conditioning of stretched elements.
constexpr double kRotationTolerance = 1e-12;

}  // namespace

FEM_CHAPTER_TESTS("08", "[ch08]")

TEST_CASE("ch08: warm-started Newton gives the SVD rotation on large rotations and stretches",
          "[ch08]") {
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> stretch(0.3, 3.0);
  for (int k = 0; k < 2000; ++k) {
    const Eigen::Matrix3d F =
        gradient_with(rng, Eigen::Vector3d(stretch(rng), stretch(rng), stretch(rng)));
    const Eigen::Matrix3d expected = polar_rotation(F);
    Eigen::Quaterniond q = near(expected, 0.5, rng);  // a previous step's rotation
    const int iterations = ch08::newton_polar_rotation(F, q);
    // A named vector: GCC 12 at -march=x86-64-v3 warns (-Warray-bounds, a false positive)
    // on the packet loads of a temporary JacobiSVD's singular values.
    const Eigen::Vector3d sigma = Eigen::JacobiSVD<Eigen::Matrix3d>(F).singularValues();
    INFO("sample " << k << ", singular values " << sigma(0) << " " << sigma(1) << " " << sigma(2));
    REQUIRE(iterations > 0);
    CHECK(iterations <= 6);
    CHECK((q.toRotationMatrix() - expected).cwiseAbs().maxCoeff() < kRotationTolerance);
  }
}

TEST_CASE(
    "ch08: the fast rotation equals the SVD path with the fallback where Newton cannot "
    "decide",
    "[ch08]") {
  std::mt19937 rng(80);
  struct Case {
    const char* name;
    Eigen::Vector3d singular_values;
    bool falls_back;  // whatever the start
  };
  const Case cases[] = {
      {"mild stretch", {1.1, 1.0, 0.9}, false},
      {"nearly flat, above the threshold", {1.0, 1.0, 0.01}, false},
      {"inverted", {1.2, 0.9, -0.8}, true},
      {"inverted, nearly flat", {1.0, 1.0, -1e-3}, true},
      {"flat", {1.0, 0.5, 1e-9}, true},
      {"collapsed to a line", {1.0, 1e-9, 1e-10}, true},
      {"collapsed to a point", {0.0, 0.0, 0.0}, true},
  };
  for (const Case& c : cases) {
    for (int k = 0; k < 200; ++k) {
      const Eigen::Matrix3d F = gradient_with(rng, c.singular_values);
      const Eigen::Matrix3d expected = polar_rotation(F);
      // Warm from a rotation near the answer, cold from the identity (any rotation angle).
      for (Eigen::Quaterniond q : {near(expected, 0.1, rng), Eigen::Quaterniond::Identity()}) {
        long long fallbacks = 0;
        const Eigen::Matrix3d R = ch08::fast_polar_rotation(F, q, fallbacks);
        INFO(c.name << ", sample " << k);
        CHECK((R - expected).cwiseAbs().maxCoeff() < kRotationTolerance);
        CHECK(std::abs(R.determinant() - 1.0) < 1e-14);
        CHECK((q.toRotationMatrix() - R).cwiseAbs().maxCoeff() < 1e-14);  // the next warm start
        if (c.falls_back) CHECK(fallbacks == 1);
      }
    }
  }
  // Warm-started near the answer, a well-shaped element never needs the SVD.
  for (int k = 0; k < 200; ++k) {
    const Eigen::Matrix3d F = gradient_with(rng, {1.1, 1.0, 0.9});
    Eigen::Quaterniond q = near(polar_rotation(F), 0.1, rng);
    long long fallbacks = 0;
    ch08::fast_polar_rotation(F, q, fallbacks);
    CHECK(fallbacks == 0);
  }
}

TEST_CASE("ch08: the closed-form blocks equal common's dfdx_block for every element", "[ch08]") {
  const Scene scene = test::test_scene("sliding");
  const Model model(scene);
  ch08::ElementKernelsStepper stepper(scene, {});
  State state = rest_state(scene);
  for (int k = 0; k < 5; ++k) stepper.step(state);  // rotated, deformed elements
  std::array<Eigen::Matrix3d, 10> K;
  double largest = 0.0;
  for (std::size_t e = 0; e < model.tets.size(); ++e) {
    const Eigen::Matrix3d R = stepper.elements().fused().rotations()[e].toRotationMatrix();
    const ch08::ElementShape& shape = stepper.elements().fused().shapes()[e];
    ch08::stiffness_blocks(ch08::rotated_gradients(R, shape.Dm_inv), shape.mu_volume,
                           shape.lambda_volume, K);
    const Matrix12d expected = -element_dfdx(model.rest[e], R);
    Matrix12d closed_form;
    for (std::size_t p = 0; p < ch08::kUpperPairs.size(); ++p) {
      const int a = ch08::kUpperPairs[p][0], b = ch08::kUpperPairs[p][1];
      closed_form.block<3, 3>(3 * a, 3 * b) = K[p];
      closed_form.block<3, 3>(3 * b, 3 * a) = K[p].transpose();
    }
    INFO("element " << e);
    CHECK((closed_form - expected).cwiseAbs().maxCoeff() <= 1e-13 * expected.cwiseAbs().maxCoeff());
    largest = std::max(largest, (R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff());
  }
  CHECK(largest > 1e-3);  // the rotations are not all the identity
}

TEST_CASE("ch08: the fused pass builds chapter 07's filtered system", "[ch08]") {
  for (const Scene& scene : {test::test_scene("cantilever"), test::driven_scene()}) {
    ch07::BlockSparseStepper separate(scene, test::tight_solver());
    ch08::ElementKernelsStepper fused(scene, test::tight_solver());
    State state = rest_state(scene);
    for (int k = 0; k < 5; ++k) {
      State a = state, b = state;  // the same input state: only rounding may differ
      separate.step(a);
      fused.step(b);
      INFO(scene.name << " step " << k);
      const Eigen::SparseMatrix<double> A07 = separate.system_matrix().to_sparse();
      const Eigen::SparseMatrix<double> difference = A07 - fused.system_matrix().to_sparse();
      CHECK(difference.norm() <= 1e-13 * A07.norm());
      const Eigen::VectorXd& b07 = separate.system_rhs();
      REQUIRE(b07.norm() > 0.0);
      // Chapter 07's forces start from R^T x_e - X_e, displacements of about 1e-2 taken from
      // positions of about 1, which loses two digits; this chapter's stress has no such
      // difference: hence a bound two digits looser than A's.
      CHECK((b07 - fused.system_rhs()).norm() <= 1e-11 * b07.norm());
      state = a;
    }
  }
}

TEST_CASE("ch08: an inverted element takes the SVD fallback and the system stays chapter 07's",
          "[ch08]") {
  const Scene scene = test::test_scene("cantilever");
  State state = rest_state(scene);
  // Push the first element's node 0 through the opposite face: the element inverts.
  const Eigen::Vector4i t = scene.mesh.tets[0];
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (int a = 1; a < 4; ++a) centroid += state.x.segment<3>(3 * t[a]) / 3.0;
  state.x.segment<3>(3 * t[0]) += 2.0 * (centroid - state.x.segment<3>(3 * t[0]));
  ch07::BlockSparseStepper separate(scene, test::tight_solver());
  ch08::ElementKernelsStepper fused(scene, test::tight_solver());
  State a = state, b = state;
  separate.step(a);
  fused.step(b);
  CHECK(fused.elements().fused().last_step_fallbacks() >= 1);
  const Eigen::SparseMatrix<double> A07 = separate.system_matrix().to_sparse();
  CHECK((A07 - fused.system_matrix().to_sparse()).norm() <= 1e-13 * A07.norm());
  const Eigen::VectorXd& b07 = separate.system_rhs();
  CHECK((b07 - fused.system_rhs()).norm() <= 1e-11 * b07.norm());
}

TEST_CASE("ch08: a stepper created on a turned body starts cold and then warm", "[ch08]") {
  // The viewer creates a stepper on whatever state the body is in: here turned by 120
  // degrees, beyond the reach of Newton from the identity, so the first step is the SVD's.
  const Scene scene = test::test_scene("sliding");
  State state = rest_state(scene);
  const Eigen::Matrix3d turn =
      Eigen::AngleAxisd(2.0944, Eigen::Vector3d(1.0, 2.0, 3.0).normalized()).toRotationMatrix();
  for (Eigen::Index i = 0; i < state.x.size(); i += 3)
    state.x.segment<3>(i) = turn * state.x.segment<3>(i);
  ch07::BlockSparseStepper separate(scene, test::tight_solver());
  ch08::ElementKernelsStepper fused(scene, test::tight_solver());
  for (int k = 0; k < 3; ++k) {
    State a = state, b = state;
    separate.step(a);
    fused.step(b);
    INFO("step " << k);
    if (k == 0)
      CHECK(fused.elements().fused().last_step_fallbacks() ==
            static_cast<long long>(scene.mesh.num_tets()));
    if (k > 0)
      CHECK(fused.elements().fused().last_step_fallbacks() == 0);  // warm from the SVD's rotations
    const Eigen::SparseMatrix<double> A07 = separate.system_matrix().to_sparse();
    CHECK((A07 - fused.system_matrix().to_sparse()).norm() <= 1e-13 * A07.norm());
    const Eigen::VectorXd& b07 = separate.system_rhs();
    CHECK((b07 - fused.system_rhs()).norm() <= 1e-11 * b07.norm());
    state = a;
  }
}

TEST_CASE("ch08: no element of the test scenes needs the SVD fallback", "[ch08]") {
  for (const Scene& scene :
       {test::test_scene("cantilever"), test::test_scene("sliding"), test::driven_scene()}) {
    ch08::ElementKernelsStepper stepper(scene, {});
    State state = rest_state(scene);
    for (int k = 0; k < 50; ++k) stepper.step(state);
    INFO(scene.name);
    CHECK(stepper.elements().fused().total_fallbacks() == 0);
  }
}

TEST_CASE("ch08: an overflowing system stops the solve at once and says so", "[ch08]") {
  // With E = 1e306 the closed-form blocks stay finite (V mu and V lambda are), and the
  // overflow appears inside the CG: it must stop there, not run to the cap on NaN.
  Scene scene = test::test_scene("cantilever");
  scene.material.youngs_modulus = 1e306;
  ch08::ElementKernelsStepper stepper(scene, {});
  State state = rest_state(scene);
  stepper.step(state);
  const StepProfile& p = stepper.profile();
  CHECK(p.cg_iterations < SolverSettings{}.max_iterations);
  CHECK_FALSE(std::isfinite(p.relative_residual));
  CHECK(state.x.allFinite());
  REQUIRE(divergence(state, p) != nullptr);
  CHECK(std::string(divergence(state, p)).find("residual is not finite") != std::string::npos);
}

TEST_CASE("ch08: zero heap allocations per step after the first", "[ch08][alloc]") {
  FEM_REQUIRE_ALLOCATION_COUNTER();
  for (const Scene& scene :
       {test::test_scene("cantilever"), test::test_scene("sliding"), test::driven_scene()}) {
    const long long count = test::allocations_per_step("08", scene);
    INFO(scene.name);
    CHECK(count == 0);
  }
}
