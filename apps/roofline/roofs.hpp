// The machine's roofs at one thread count, and the time they allow a phase's work.
#pragma once

#include <string>
#include <vector>

#include "apps/roofline/bandwidth.hpp"
#include "apps/roofline/peak.hpp"
#include "apps/roofline/work.hpp"

namespace fem::roofline {

struct LevelRoof {
  MemoryLevel level;
  double read = 0.0;       // bytes/s: the roof (read_bandwidth)
  double eigen_sum = 0.0;  // bytes/s: the second measurement (eigen_sum_bandwidth)
  double triad = 0.0;      // bytes/s: STREAM's triad as STREAM counts it
};

struct Roofs {
  int threads = 1;
  std::vector<LevelRoof> levels;               // innermost first, memory last
  double peak_double = 0.0, peak_float = 0.0;  // flops/s
};

// Every roof at `threads` threads, each kernel run for about `seconds`.
Roofs measure_roofs(const std::vector<CacheLevel>& caches, int threads, double seconds);

// The innermost level whose share per thread holds the working set (memory if none).
const LevelRoof& fitting_level(const Roofs& roofs, double working_set);

// The time the roofs allow a phase: its bytes at the bandwidth of the level its working set
// fits, or its flops at the peak (double and float flops each at their own), the longer.
double bound_seconds(const Roofs& roofs, const PhaseWork& work);

}  // namespace fem::roofline
