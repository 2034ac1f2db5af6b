// The pieces of OpenMP this chapter and the later ones need, behind a guard so that they also
// build (and run on one thread) without OpenMP: a region, a static share of a loop, the fixed
// partition of rows every deterministic loop shares out, and an exact sum of counts.
#pragma once

#include <algorithm>
#include <atomic>
#include <vector>

#include "common/sync_hook.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace fem::ch09 {

// The synchronizations the threads have met, in all steps of every stepper so far: parallel
// regions opened with more than one thread, and barriers (each worksharing loop's end, each
// single's), counted once per team by its thread 0, for the roofline's cost of waiting. A
// relaxed add from one thread per barrier: nanoseconds beside the barrier's own cost.
struct SyncCounts {
  std::atomic<long long> regions{0}, barriers{0};

  Synchronizations snapshot() const {
    return {regions.load(std::memory_order_relaxed), barriers.load(std::memory_order_relaxed)};
  }
};
inline SyncCounts& sync_counts() {
  static SyncCounts counts;
  return counts;
}
// PhaseTimer's hook (common/sync_hook.hpp), set before main by every program that links code
// which counts, so that each phase of a step carries its own count (StepProfile).
inline const bool sync_count_hook_set = (
    sync_count_hook = [] { return sync_counts().snapshot(); }, true);
inline void count_barrier() {
#ifdef _OPENMP
  if (omp_get_thread_num() != 0) return;
#endif
  sync_counts().barriers.fetch_add(1, std::memory_order_relaxed);
}

// Runs body() on every thread of a team, or straight on the calling thread when the team
// would have one thread. Why not always a region: libgomp keeps the last team for reuse
// only when it has more than one thread (gomp_team_end in libgomp/team.c frees a team of
// one), so a region of one thread costs a malloc and a free each time, and one thread
// needs no region. The worksharing loops and barriers inside body() are orphaned
// constructs: outside a region they run as a team of one (every iteration, no wait).
template <class Body>
void run_parallel(Body&& body) {
#ifdef _OPENMP
  if (omp_get_max_threads() > 1) {
    sync_counts().regions.fetch_add(1, std::memory_order_relaxed);
#pragma omp parallel
    body();
    return;
  }
#endif
  body();
}

// `#pragma omp for schedule(static)` written out, for `for (const int c : StaticShare(count))`
// called by every thread of a team: this thread's contiguous block of [0, count), as the
// static schedule hands them out, and the barrier that ends a worksharing loop, run by the
// destructor when the loop is over (the range lives as long as the loop). Why not the
// pragma: Debian's libomp (Clang's OpenMP runtime) formats a debug trace string into a heap
// buffer in every __kmpc_for_static_init, release build or not, so every worksharing loop
// would allocate and the step would not be allocation-free (the chapters' zero-allocation
// tests would fail under the clang preset); GCC's libgomp allocates nothing there. Outside a
// parallel region (one thread) the block is the whole range and the barrier does nothing.
class StaticShare {
 public:
  explicit StaticShare(int count) : StaticShare(0, count) {}
  // This thread's block of [first, last).
  StaticShare(int first, int last) {
#ifdef _OPENMP
    const long long threads = omp_get_num_threads(), thread = omp_get_thread_num();
#else
    const long long threads = 1, thread = 0;
#endif
    const long long count = last - first;
    begin_ = first + static_cast<int>(count * thread / threads);
    end_ = first + static_cast<int>(count * (thread + 1) / threads);
  }
  ~StaticShare() {
    count_barrier();
#pragma omp barrier
  }
  StaticShare(const StaticShare&) = delete;
  StaticShare& operator=(const StaticShare&) = delete;

  struct Iterator {
    int i;
    int operator*() const { return i; }
    Iterator& operator++() {
      ++i;
      return *this;
    }
    bool operator!=(const Iterator& other) const { return i != other.i; }
  };
  Iterator begin() const { return {begin_}; }
  Iterator end() const { return {end_}; }

 private:
  int begin_ = 0, end_ = 0;
};

// A fixed partition of `rows` rows (of a block compressed pattern, row_start with rows + 1
// entries) into `count` ranges of about the same number of stored blocks: range c holds rows
// start[c] .. start[c+1]-1. Equal blocks rather than equal rows, because an SpMV costs per
// block. A function of the pattern and the count alone, never of the thread count: every
// loop over the ranges, and every sum of per-range sums, is then the same for any team.
inline std::vector<int> equal_block_partition(const std::vector<int>& row_start, int count) {
  const int rows = static_cast<int>(row_start.size()) - 1;
  const long long blocks = row_start.back();
  std::vector<int> start(count + 1, rows);
  start[0] = 0;
  for (int c = 1, i = 0; c < count; ++c) {
    const long long target = blocks * c / count;
    while (i < rows && row_start[i] < target) ++i;
    start[c] = i;
  }
  return start;
}

// body(first, last) on each range of a fixed partition (equal_block_partition): shared out
// between the threads of the team by a StaticShare (a static schedule, a barrier at its end)
// when collective, all on this thread otherwise (inside a `single`, where no loop may be
// shared).
template <class Body>
void for_parts(const std::vector<int>& start, bool collective, Body&& body) {
  const int count = static_cast<int>(start.size()) - 1;
  if (collective) {
    for (const int p : StaticShare(count)) body(start[p], start[p + 1]);
  } else {
    for (int p = 0; p < count; ++p) body(start[p], start[p + 1]);
  }
}

// body() on one thread of the team (the others wait at the end), or here.
template <class Body>
void on_one_thread(bool collective, Body&& body) {
  if (collective) {
    count_barrier();
#pragma omp single
    body();
  } else {
    body();
  }
}

// total += mine, from every thread once. An integer sum is exact in any order, so this
// atomic leaves the result independent of the threads. (Not an OpenMP reduction: OpenMP
// requires a reduction variable of an orphaned loop to be shared in the enclosing region,
// which a variable a lambda captures is not visibly, and Clang holds to it: "reduction
// variable must be shared".)
inline void add_count(long long& total, long long mine) {
#pragma omp atomic
  total += mine;
}

}  // namespace fem::ch09
