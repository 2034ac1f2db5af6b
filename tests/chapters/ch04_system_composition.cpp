// Chapter 04: A composed in one pass over the value arrays equals the sparse expression.
#include "catch2_compat.hpp"
#include "chapters/03_indexed_access/stepper.hpp"
#include "chapters/04_system_composition/stepper.hpp"
#include "support.hpp"

using namespace fem;

FEM_CHAPTER_TESTS("04", "[ch04]")

TEST_CASE("ch04: the composed system equals chapter 03's sparse expression", "[ch04]") {
  const Scene scene = test::driven_scene();
  ch03::IndexedAccessStepper expression(scene, test::tight_solver());
  ch04::SystemCompositionStepper one_pass(scene, test::tight_solver());
  State state = rest_state(scene);
  for (int k = 0; k < 5; ++k) {
    // Both build their system from the same state, so only rounding can differ.
    State a = state, b = state;
    expression.step(a);
    one_pass.step(b);
    const Eigen::SparseMatrix<double> difference =
        expression.system_matrix() - one_pass.system_matrix();
    CHECK(difference.norm() <= 1e-14 * expression.system_matrix().norm());
    CHECK((expression.system_rhs() - one_pass.system_rhs()).norm() <=
          1e-13 * expression.system_rhs().norm());
    state = a;
  }
}

TEST_CASE("ch04: allocates fewer per step than chapter 03", "[ch04][alloc]") {
  FEM_REQUIRE_ALLOCATION_COUNTER();
  for (const char* name : {"cantilever", "sliding"}) {
    const Scene scene = test::test_scene(name);
    const long long ch03 = test::allocations_per_step("03", scene);
    const long long ch04 = test::allocations_per_step("04", scene);
    INFO(name << ": 03 allocates " << ch03 << ", 04 allocates " << ch04 << " per step");
    REQUIRE(ch04 >= 0);
    CHECK(ch04 < ch03);
  }
}

TEST_CASE("ch04: the composition phase allocates nothing", "[ch04][alloc]") {
  FEM_REQUIRE_ALLOCATION_COUNTER();
  for (const char* name : {"cantilever", "sliding"}) {
    const Scene scene = test::test_scene(name);
    ch03::IndexedAccessStepper before(scene, {});
    ch04::SystemCompositionStepper after(scene, {});
    State a = rest_state(scene), b = rest_state(scene);
    for (int k = 0; k < 3; ++k) {
      before.step(a);
      after.step(b);
    }
    INFO(name << ": composition allocations 03: " << before.profile().compose.allocations
              << ", 04: " << after.profile().compose.allocations);
    // The sparse expressions did, by Eigen 3.4's rule (assign_sparse_to_sparse): per
    // statement one temporary, 1 outer index + 2 arrays x 5 reallocations on the test mesh
    // (reserve 2 x 570, doubled to 16272 non-zeros), as `fem_lessons compose` prints.
    CHECK(before.profile().compose.allocations == 2 * (1 + 2 * 5));
    CHECK(after.profile().compose.allocations == 0);
    CHECK(after.profile().dfdx.allocations == 0);
  }
}
