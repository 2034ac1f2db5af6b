// The timing both roofs share: a kernel on every thread of a team at once, each thread timing
// its own runs, the best of several timings.
#pragma once

#include <algorithm>
#include <atomic>
#include <chrono>
#include <limits>

namespace fem::roofline {

// The best rate of a kernel run by `threads` threads at once, each on its own data made by
// make() inside the team (so that the first touch places it by its thread). Each thread times
// its own runs: `inner` calls per timing, doubled until a timing lasts long enough to trust
// the clock, repeated until the first thread has spent about `seconds` (the others stop with
// it, so that all of them run all along). The team's rate is the sum of each thread's best:
// a thread that another program delays then costs its own timings, not everyone's (a timing
// between barriers would wait for the slowest). Returns units per second, with run(state)
// doing `units` units per call.
template <class Make, class Run>
double best_rate(int threads, double seconds, double units, Make make, Run run) {
  using Clock = std::chrono::steady_clock;
  const double min_timing = std::max(2e-3, seconds / 40);
  double total = 0.0, sink = 0.0;
  std::atomic<bool> stop{false};
#pragma omp parallel num_threads(threads) reduction(+ : total, sink)
  {
    auto state = make();
    double best = 0.0, spent = 0.0;
    int inner = 1, timed = 0;
#pragma omp barrier
    while (!stop.load(std::memory_order_relaxed)) {
      const Clock::time_point start = Clock::now();
      for (int i = 0; i < inner; ++i) {
        sink += run(state);
        // The data may have changed, as far as the compiler knows (GCC's and Clang's empty
        // asm with a memory clobber): every call reads it again instead of being hoisted.
        asm volatile("" ::: "memory");
      }
      const double t = std::chrono::duration<double>(Clock::now() - start).count();
      spent += t;
      if (t < min_timing) {
        inner *= 2;
        continue;
      }
      best = std::max(best, units * inner / t);
      if ((spent > seconds && ++timed >= 3) || timed >= 50) stop = true;
    }
    total += best;
  }
  // The sums feed nothing else; the comparison keeps the compiler from dropping them.
  return sink == std::numeric_limits<double>::infinity() ? 0.0 : total;
}

}  // namespace fem::roofline
