// Chapter 07: the block sparse matrix computes what Eigen's computes, and the stepper
// still matches chapter 01 without allocating.
#include "catch2_compat.hpp"
#include "chapters/05_inplace_constraints/stepper.hpp"
#include "chapters/07_block_sparse/lesson.hpp"
#include "chapters/07_block_sparse/stepper.hpp"
#include "support.hpp"

using namespace fem;

TEST_CASE("ch07: block SpMV equals Eigen's SpMV of the same matrix", "[ch07]") {
  const Scene scene = test::test_scene("sliding");
  ch07::BlockSparseStepper stepper(scene, {});
  State state = rest_state(scene);
  for (int k = 0; k < 3; ++k) stepper.step(state);
  const ch07::BlockSparseMatrix& A = stepper.system_matrix();
  const Eigen::SparseMatrix<double> eigen = A.to_sparse();
  std::srand(3);
  const Eigen::VectorXd x = Eigen::VectorXd::Random(eigen.cols());
  const Eigen::VectorXd expected = eigen * x;
  Eigen::VectorXd y(x.size());
  A.multiply(x, y);
  CHECK((y - expected).norm() <= 1e-12 * expected.norm());
  // Symmetric storage: only the upper blocks, the lower ones by transposition.
  const ch07::BlockSparseMatrix upper = ch07::upper(A);
  CHECK(upper.blocks.size() < A.blocks.size());
  ch07::multiply_upper(upper, x, y);
  CHECK((y - expected).norm() <= 1e-12 * expected.norm());
}

TEST_CASE("ch07: the filtered block system equals chapter 05's", "[ch07]") {
  // The driven scene: z != 0, so S (b - A z) goes through the transposed-block lookup.
  const Scene scene = test::driven_scene();
  ch05::InplaceConstraintsStepper scalar(scene, test::tight_solver());
  ch07::BlockSparseStepper blocks(scene, test::tight_solver());
  State state = rest_state(scene);
  for (int k = 0; k < 3; ++k) {
    State a = state, b = state;  // the same input state: only rounding may differ
    scalar.step(a);
    blocks.step(b);
    const Eigen::SparseMatrix<double> difference =
        scalar.system_matrix() - blocks.system_matrix().to_sparse();
    CHECK(difference.norm() <= 1e-13 * scalar.system_matrix().norm());
    CHECK((scalar.system_rhs() - blocks.system_rhs()).norm() <= 1e-13 * scalar.system_rhs().norm());
    state = a;
  }
}

FEM_CHAPTER_TESTS("07", "[ch07]")

TEST_CASE("ch07: zero heap allocations per step after the first", "[ch07][alloc]") {
  FEM_REQUIRE_ALLOCATION_COUNTER();
  for (const char* name : {"cantilever", "sliding"}) {
    const long long count = test::allocations_per_step("07", test::test_scene(name));
    INFO(name);
    CHECK(count == 0);
  }
}
