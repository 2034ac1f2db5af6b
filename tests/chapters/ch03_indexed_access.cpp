// Chapter 03: the offset table fills df/dx exactly as coeffRef does, without searching.
#include "catch2_compat.hpp"
#include "chapters/02_noalias/stepper.hpp"
#include "chapters/03_indexed_access/stepper.hpp"
#include "common/alloc_counter.hpp"
#include "support.hpp"

using namespace fem;

FEM_CHAPTER_TESTS("03", "[ch03]")

TEST_CASE("ch03: the offset table gives bit-identical df/dx to the coeffRef fill", "[ch03]") {
  const Scene scene = test::test_scene("sliding");
  ch02::NoAliasStepper by_coeff_ref(scene, test::tight_solver());
  ch03::IndexedAccessStepper by_table(scene, test::tight_solver());
  State a = rest_state(scene), b = rest_state(scene);
  for (int k = 0; k < 10; ++k) {
    by_coeff_ref.step(a);
    by_table.step(b);
    const auto& A = by_coeff_ref.dfdx();
    const auto& B = by_table.dfdx();
    REQUIRE(A.nonZeros() == B.nonZeros());
    // Same pattern, and every value equal to the last bit (the same sums in the same order).
    CHECK(std::equal(A.innerIndexPtr(), A.innerIndexPtr() + A.nonZeros(), B.innerIndexPtr()));
    CHECK(std::equal(A.valuePtr(), A.valuePtr() + A.nonZeros(), B.valuePtr()));
  }
  CHECK(by_table.dfdx().isCompressed());
}

TEST_CASE("ch03: allocates no more per step than chapter 02", "[ch03][alloc]") {
  FEM_REQUIRE_ALLOCATION_COUNTER();
  for (const char* name : {"cantilever", "sliding"}) {
    const Scene scene = test::test_scene(name);
    const long long ch02 = test::allocations_per_step("02", scene);
    const long long ch03 = test::allocations_per_step("03", scene);
    INFO(name << ": 02 allocates " << ch02 << ", 03 allocates " << ch03 << " per step");
    // The table changes df/dx construction only, which allocated nothing already.
    CHECK(ch03 == ch02);
  }
}
