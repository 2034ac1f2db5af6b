// Counts heap allocations, for tests and benchmarks: "zero allocations per step" is a
// claim this project asserts, so it needs a counter that sees every allocation.
//
// It interposes malloc, calloc, realloc, free, posix_memalign, aligned_alloc and memalign
// (forwarding to the C library's own, found with dlsym(RTLD_NEXT): glibc, musl and macOS
// alike) and replaces the global operator new and delete, so that both of Eigen's sources of
// memory are seen: dense storage comes from std::malloc (Eigen/src/Core/util/Memory.h:
// aligned_malloc, which has no hook of its own), sparse storage from new[] and std::malloc.
//
// Why not Eigen's own EIGEN_RUNTIME_NO_MALLOC? It only guards Eigen's dense
// aligned_malloc (SparseMatrix and CompressedStorage allocate with new[] and std::realloc,
// unseen), it asserts instead of counting, and it disappears under NDEBUG, that is in the
// release builds that the benchmarks measure.
//
// Link the object library fem_alloc_counter into a program to enable it; the steppers do
// not depend on it. Sanitizer builds interpose malloc themselves, so there
// (FEM_ALLOC_COUNTER_DISABLED) enabled() is false and every count is zero.
#pragma once

namespace fem::alloc {

struct Counts {
  long long allocations = 0;    // malloc, calloc, realloc (to a non-zero size), memalign & co
  long long deallocations = 0;  // free of a non-null pointer
  long long bytes = 0;          // bytes requested by those allocations
  long long new_calls = 0;      // how many of the allocations came through operator new
};

bool enabled();
Counts counts();  // cumulative since the program started, all threads

// What happened between construction and now: `alloc::Scope s; work(); s.allocations()`.
class Scope {
 public:
  Scope() : start_(counts()) {}
  Counts delta() const {
    const Counts now = counts();
    return {now.allocations - start_.allocations, now.deallocations - start_.deallocations,
            now.bytes - start_.bytes, now.new_calls - start_.new_calls};
  }
  long long allocations() const { return delta().allocations; }
  long long deallocations() const { return delta().deallocations; }
  long long bytes() const { return delta().bytes; }

 private:
  Counts start_;
};

}  // namespace fem::alloc
