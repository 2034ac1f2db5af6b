// The timing every roof shares: a kernel on every thread of a team at once, the team timed
// as a whole, the best of several timings.
#pragma once

#include <algorithm>
#include <chrono>
#include <limits>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif
#if defined(__linux__)
#include <pthread.h>
#include <sched.h>
#endif

namespace fem::roofline {

constexpr int kRoofTimings = 5;

// The CPUs this process may run on, in order (Linux; empty elsewhere).
inline std::vector<int> allowed_cpus() {
  std::vector<int> cpus;
#if defined(__linux__)
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof set, &set) == 0)
    for (int c = 0; c < CPU_SETSIZE; ++c)
      if (CPU_ISSET(c, &set)) cpus.push_back(c);
#endif
  return cpus;
}

// The calling thread on one CPU while it lives, as likwid-bench pins each of its threads
// (likwid-pin): no thread of a team migrates onto another's core, or away from the cache its
// data are in, during a timing. Its own affinity back afterwards, since the OpenMP runtime
// keeps its threads for the chapters, which do not pin. A CPU < 0: not pinned.
class PinnedThread {
 public:
  explicit PinnedThread(int cpu) {
#if defined(__linux__)
    if (cpu < 0 || pthread_getaffinity_np(pthread_self(), sizeof saved_, &saved_) != 0) return;
    cpu_set_t one;
    CPU_ZERO(&one);
    CPU_SET(cpu, &one);
    pinned_ = pthread_setaffinity_np(pthread_self(), sizeof one, &one) == 0;
#else
    (void)cpu;
#endif
  }
  ~PinnedThread() {
#if defined(__linux__)
    if (pinned_) pthread_setaffinity_np(pthread_self(), sizeof saved_, &saved_);
#endif
  }
  PinnedThread(const PinnedThread&) = delete;
  PinnedThread& operator=(const PinnedThread&) = delete;

 private:
#if defined(__linux__)
  cpu_set_t saved_;
#endif
  bool pinned_ = false;
};

// The best rate of a kernel run by `threads` threads at once, each on its own data made by
// make() inside the team (so that the first touch places it by its thread), thread k pinned
// to the k-th CPU the process may use (PinnedThread) from before make() to the end. One timing is
// the team's: from the barrier that starts every thread to the barrier after the last one
// ends, `inner` calls per thread in between (doubled until a timing lasts long enough to
// trust the clock); the rate is the units of all threads over that wall time, so that a
// shared level (L3, memory) is credited only with what it sustains for all threads at once.
// `timings` timings of about seconds / timings each, repeated for about `seconds` (at least 3,
// or 1 where timings is 1); the best is the roof. Its likwid-bench check (likwid.hpp) is
// sampled the same way, as many runs as long: a virtual machine's neighbours move a level's
// rate between timings, and the best of many short timings catches a quieter moment than the
// best of a few long ones (the 2-core Zen 5 VM's memory read at one thread, likwid-bench's runs
// of 0.12 s one after another: 37.3 to 44.5 GB/s).
// Returns units per second, with run(state) doing `units` units per call on one thread.
template <class Make, class Run>
double best_rate(int threads, double seconds, double units, Make make, Run run,
                 int timings = kRoofTimings) {
  using Clock = std::chrono::steady_clock;
  const double min_timing = std::max(2e-3, seconds / timings);
  const int least = std::min(3, timings);
  double best = 0.0, sink = 0.0, spent = 0.0;
  int inner = 1, timed = 0;
  bool stop = false;
  Clock::time_point start;
  const std::vector<int> cpus = allowed_cpus();
#pragma omp parallel num_threads(threads) reduction(+ : sink)
  {
#ifdef _OPENMP
    const std::size_t k = std::size_t(omp_get_thread_num());
#else
    const std::size_t k = 0;
#endif
    const PinnedThread pinned(k < cpus.size() && int(cpus.size()) >= threads ? cpus[k] : -1);
    auto state = make();
    while (true) {
#pragma omp barrier
#pragma omp single
      start = Clock::now();  // single's own barrier starts every thread together
      for (int i = 0; i < inner; ++i) {
        sink += run(state);
        // The data may have changed, as far as the compiler knows (GCC's and Clang's empty
        // asm with a memory clobber): every call reads it again instead of being hoisted.
        asm volatile("" ::: "memory");
      }
#pragma omp barrier
#pragma omp single
      {
        const double t = std::chrono::duration<double>(Clock::now() - start).count();
        spent += t;
        if (t < min_timing) {
          inner *= 2;
        } else {
          best = std::max(best, units * threads * inner / t);
          ++timed;
          stop = (spent > seconds && timed >= least) || timed >= 10 * timings;
        }
      }  // single's barrier: every thread sees stop
      if (stop) break;
    }
  }
  // The sums feed nothing else; the comparison keeps the compiler from dropping them.
  return sink == std::numeric_limits<double>::infinity() ? 0.0 : best;
}

}  // namespace fem::roofline
