// Chapter 05: the filter applied in place equals the explicit S A S^T + I - S.
#include <Eigen/Cholesky>

#include "catch2_compat.hpp"
#include "chapters/01_naive/stepper.hpp"
#include "chapters/05_inplace_constraints/stepper.hpp"
#include "support.hpp"

using namespace fem;

FEM_CHAPTER_TESTS("05", "[ch05]")

TEST_CASE("ch05: the in-place filtered system equals S A S^T + I - S entry by entry", "[ch05]") {
  const Scene scene = test::driven_scene();
  int kinds[3] = {0, 0, 0};
  for (const auto& c : scene.constraints) ++kinds[static_cast<int>(c.kind)];
  REQUIRE(kinds[0] > 0);  // plane
  REQUIRE(kinds[1] > 0);  // line
  REQUIRE(kinds[2] > 0);  // fixed
  ch01::NaiveStepper explicit_filter(scene, test::tight_solver());
  ch05::InplaceConstraintsStepper in_place(scene, test::tight_solver());
  State state = rest_state(scene);
  for (int k = 0; k < 5; ++k) {
    // Both build their system from the same state, so only rounding can differ.
    State a = state, b = state;
    explicit_filter.step(a);
    in_place.step(b);
    state = a;
    const Eigen::MatrixXd A01 = explicit_filter.system_matrix();
    const Eigen::MatrixXd A05 = in_place.system_matrix();
    CHECK((A01 - A05).cwiseAbs().maxCoeff() <= 1e-13 * A01.cwiseAbs().maxCoeff());
    const Eigen::VectorXd& b01 = explicit_filter.system_rhs();
    const Eigen::VectorXd& b05 = in_place.system_rhs();
    REQUIRE(b01.norm() > 0.0);
    CHECK((b01 - b05).cwiseAbs().maxCoeff() <= 1e-13 * b01.cwiseAbs().maxCoeff());
  }
  // The filtered system stays symmetric positive definite.
  const Eigen::MatrixXd A = in_place.system_matrix();
  CHECK((A - A.transpose()).norm() <= 1e-14 * A.norm());
  CHECK(Eigen::LLT<Eigen::MatrixXd>(A).info() == Eigen::Success);
}

TEST_CASE("ch05: composition and constraints allocate nothing", "[ch05][alloc]") {
  FEM_REQUIRE_ALLOCATION_COUNTER();
  for (const Scene& scene : {test::test_scene("cantilever"), test::driven_scene()}) {
    ch05::InplaceConstraintsStepper stepper(scene, {});
    State state = rest_state(scene);
    for (int k = 0; k < 3; ++k) {
      stepper.step(state);
      const StepProfile& p = stepper.profile();
      INFO(scene.name << " step " << k << ": constraints " << p.constraints.allocations
                      << ", compose " << p.compose.allocations << ", solve "
                      << p.solve.allocations);
      if (k == 0) continue;  // the first step sizes the work vectors
      CHECK(p.dfdx.allocations == 0);
      CHECK(p.compose.allocations == 0);
      CHECK(p.constraints.allocations == 0);
      CHECK(p.step.allocations == p.solve.allocations);  // only Eigen's CG is left
    }
  }
}
