// The two pieces of OpenMP this chapter needs, behind a guard so that the chapter also
// builds (and runs on one thread) without OpenMP.
#pragma once

#ifdef _OPENMP
#include <omp.h>
#endif

namespace fem::ch09 {

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
  ~StaticShare(){
#pragma omp barrier
  } StaticShare(const StaticShare&) = delete;
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

}  // namespace fem::ch09
