// The allocation counter counts known allocations exactly.
#include <Eigen/SparseCore>
#include <cstdlib>
#include <vector>

#include "catch2_compat.hpp"
#include "common/alloc_counter.hpp"

using namespace fem;

namespace {

// Keeps the optimizer from removing an allocation whose result is never used.
void escape(const void* p) { asm volatile("" : : "g"(p) : "memory"); }

}  // namespace

#define REQUIRE_COUNTER_ON()                                   \
  if (!alloc::enabled()) {                                     \
    SUCCEED("allocation counting is off in sanitizer builds"); \
    return;                                                    \
  }

TEST_CASE("a std::vector reserve is one allocation", "[alloc]") {
  REQUIRE_COUNTER_ON();
  alloc::Scope scope;
  {
    std::vector<double> v;
    v.reserve(100);
    escape(v.data());
  }
  CHECK(scope.allocations() == 1);
  CHECK(scope.deallocations() == 1);
  CHECK(scope.bytes() == 800);
  CHECK(scope.delta().new_calls == 1);
}

TEST_CASE("an Eigen dense vector is one allocation, a fixed-size matrix none", "[alloc]") {
  REQUIRE_COUNTER_ON();
  alloc::Scope dynamic;
  {
    Eigen::VectorXd v(1000);
    escape(v.data());
  }
  CHECK(dynamic.allocations() == 1);
  CHECK(dynamic.delta().new_calls == 0);  // Eigen's dense storage comes from malloc
  alloc::Scope fixed;
  {
    Eigen::Matrix3d m = Eigen::Matrix3d::Identity();
    escape(m.data());
  }
  CHECK(fixed.allocations() == 0);
}

TEST_CASE("a SparseMatrix insertion is seen", "[alloc]") {
  REQUIRE_COUNTER_ON();
  Eigen::SparseMatrix<double> m(10, 10);  // allocates its outer index array
  alloc::Scope scope;
  m.insert(3, 4) = 1.0;
  // Eigen 3.4: the first insert into a compressed matrix switches it to uncompressed mode,
  // which allocates the per-column non-zero counts with std::malloc, then reserves room
  // for the values and the inner indices with new[] each: three allocations, two of them
  // through operator new.
  CHECK(scope.allocations() == 3);
  CHECK(scope.delta().new_calls == 2);
  alloc::Scope again;
  m.insert(5, 4) = 2.0;  // room was reserved: no allocation
  CHECK(again.allocations() == 0);
}

TEST_CASE("new/delete, calloc, realloc and the aligned allocators are each counted", "[alloc]") {
  REQUIRE_COUNTER_ON();
  alloc::Scope scope;
  int* i = new int(3);
  escape(i);
  delete i;
  CHECK(scope.allocations() == 1);
  CHECK(scope.deallocations() == 1);

  alloc::Scope c;
  void* p = std::calloc(10, 8);
  escape(p);
  p = std::realloc(p, 1000);
  escape(p);
  std::free(p);
  CHECK(c.allocations() == 2);
  CHECK(c.deallocations() == 1);

  alloc::Scope a;
  void* q = nullptr;
  REQUIRE(posix_memalign(&q, 64, 256) == 0);
  escape(q);
  std::free(q);
  void* r = std::aligned_alloc(64, 256);
  escape(r);
  std::free(r);
  CHECK(a.allocations() == 2);
  CHECK(a.deallocations() == 2);
  alloc::Scope none;
  std::free(nullptr);
  CHECK(none.deallocations() == 0);
}
