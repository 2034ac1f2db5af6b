#include "apps/roofline/sync_cost.hpp"

#include <algorithm>
#include <chrono>
#include <limits>

namespace fem::roofline {

namespace {

using Clock = std::chrono::steady_clock;
constexpr int kRepeats = 7;
constexpr int kCount = 2000;  // synchronizations per timing: long enough for the clock

template <class Loop>
double best_per_sync(Loop loop) {
  double best = std::numeric_limits<double>::infinity();
  for (int r = 0; r < kRepeats; ++r) {
    const Clock::time_point start = Clock::now();
    loop();
    best = std::min(best, std::chrono::duration<double>(Clock::now() - start).count() / kCount);
  }
  return best;
}

}  // namespace

double barrier_seconds(int threads) {
  if (threads <= 1) return 0.0;
  return best_per_sync([threads] {
#pragma omp parallel num_threads(threads)
    for (int i = 0; i < kCount; ++i) {
#pragma omp barrier
    }
  });
}

double region_seconds(int threads) {
  if (threads <= 1) return 0.0;
  return best_per_sync([threads] {
    for (int i = 0; i < kCount; ++i) {
#pragma omp parallel num_threads(threads)
      {
        asm volatile("" ::: "memory");  // a region with a body the compiler keeps
      }
    }
  });
}

}  // namespace fem::roofline
