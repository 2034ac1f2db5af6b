// Chapter 06: our PCG solves what Eigen's CG solves, and the step allocates nothing.
#include <Eigen/Cholesky>

#include "catch2_compat.hpp"
#include "chapters/06_custom_pcg/stepper.hpp"
#include "support.hpp"

using namespace fem;

FEM_CHAPTER_TESTS("06", "[ch06]")

TEST_CASE("ch06: zero heap allocations per step after the first", "[ch06][alloc]") {
  FEM_REQUIRE_ALLOCATION_COUNTER();
  for (const char* name : {"cantilever", "sliding"}) {
    const long long count = test::allocations_per_step("06", test::test_scene(name));
    INFO(name);
    CHECK(count == 0);
  }
}

TEST_CASE("ch06: pcg_solve reaches the requested tolerance on an SPD system", "[ch06]") {
  // A 1D Laplacian plus a small mass term: SPD, condition number about 4e4.
  const int n = 300;
  std::vector<Eigen::Triplet<double>> t;
  for (int i = 0; i < n; ++i) {
    t.emplace_back(i, i, 2.0 + 1e-4);
    if (i > 0) t.emplace_back(i, i - 1, -1.0);
    if (i + 1 < n) t.emplace_back(i, i + 1, -1.0);
  }
  Eigen::SparseMatrix<double> A(n, n);
  A.setFromTriplets(t.begin(), t.end());
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(n, -1.0, 2.0);
  for (const double tolerance : {1e-4, 1e-7, 1e-10}) {
    SolverSettings settings;
    settings.tolerance = tolerance;
    settings.max_iterations = 5000;
    ch06::PcgWorkspace work;
    Eigen::VectorXd y = Eigen::VectorXd::Zero(n);
    const auto result = ch06::pcg_solve(A, b, {}, ch06::diagonal_offsets(A), settings, work, y);
    INFO("tolerance " << tolerance << ": " << result.iterations << " iterations");
    CHECK(result.converged);
    CHECK(result.relative_residual <= tolerance);
    // The reported residual is the true one, not a recurrence that drifted.
    CHECK((b - A * y).norm() / b.norm() <= 2.0 * tolerance);
  }
}

TEST_CASE("ch06: with a filtered singular system the constrained components are exact", "[ch06]") {
  // A singular matrix (a free-floating body has rigid modes) made SPD by the filter:
  // fixed node 0 and a plane-constrained node 1 pin it. The filtered solve must return
  // y with exactly zero constrained components, so that dv = y + z has exactly z there.
  const Scene scene = test::test_scene("sliding");
  ch06::CustomPcgStepper stepper(scene, test::tight_solver());
  State state = rest_state(scene);
  stepper.step(state);
  const auto& A = stepper.system_matrix();
  const Eigen::VectorXd& b = stepper.system_rhs();
  ch06::PcgWorkspace work;
  // Start from a guess with garbage in the constrained directions: the filter removes it.
  Eigen::VectorXd y = Eigen::VectorXd::Ones(b.size());
  const auto result = ch06::pcg_solve(A, b, scene.constraints, ch06::diagonal_offsets(A),
                                      test::tight_solver(), work, y);
  REQUIRE(result.converged);
  for (const auto& c : scene.constraints) {
    const Eigen::Vector3d constrained =
        (Eigen::Matrix3d::Identity() - c.filter) * y.segment<3>(3 * c.node);
    CHECK(constrained.norm() <= 1e-15 * y.norm());
  }
  // And it is the solution: compare with a dense Cholesky of the same system.
  const Eigen::VectorXd exact = Eigen::MatrixXd(A).llt().solve(b);
  CHECK((y - exact).norm() <= 1e-9 * exact.norm());
}
