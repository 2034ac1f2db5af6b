// Chapter 02: the same physics as chapter 01, fewer allocations, and the per-statement
// counts that the chapter's README shows.
#include "catch2_compat.hpp"
#include "chapters/02_noalias/statements.hpp"
#include "common/alloc_counter.hpp"
#include "support.hpp"

using namespace fem;

FEM_CHAPTER_TESTS("02", "[ch02]")

TEST_CASE("ch02: allocates strictly fewer per step than chapter 01", "[ch02][alloc]") {
  FEM_REQUIRE_ALLOCATION_COUNTER();
  for (const char* name : {"cantilever", "sliding"}) {
    const Scene scene = test::test_scene(name);
    const long long ch01 = test::allocations_per_step("01", scene);
    const long long ch02 = test::allocations_per_step("02", scene);
    INFO(name << ": 01 allocates " << ch01 << ", 02 allocates " << ch02 << " per step");
    REQUIRE(ch01 > 0);  // -1 would mean the count changed from step to step
    REQUIRE(ch02 > 0);  // the sparse expressions, S and CG still allocate
    CHECK(ch02 < ch01);
  }
}

TEST_CASE("ch02: every rewritten statement allocates less than the original", "[ch02][alloc]") {
  FEM_REQUIRE_ALLOCATION_COUNTER();
  const auto counts = ch02::count_statements(test::test_scene("sliding"));
  REQUIRE(counts.size() == 5);
  for (const auto& c : counts) {
    INFO(c.before_code << ": " << c.before << "  ->  " << c.after_code << ": " << c.after);
    CHECK(c.after < c.before);
  }
  // The vector statements themselves allocate nothing once rewritten; the solve keeps
  // the work vectors of Eigen's CG (chapter 06 removes them).
  CHECK(counts[0].after == 0);
  CHECK(counts[1].after == 0);
  CHECK(counts[2].after == 0);
  CHECK(counts[3].after == counts[3].before - 1);
  CHECK(counts[4].after == 0);
}
