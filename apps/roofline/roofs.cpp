#include "apps/roofline/roofs.hpp"

#include <algorithm>

#include "common/lesson.hpp"

namespace fem::roofline {

Roofs measure_roofs(const std::vector<CacheLevel>& caches, int threads, double seconds) {
  Roofs roofs;
  roofs.threads = threads;
  for (const MemoryLevel& level : memory_levels(caches, threads)) {
    progress("roofline: " + level.name + " bandwidth at " + std::to_string(threads) + " thread(s)");
    LevelRoof roof{level, 0.0, 0.0, 0.0};
    roof.read = read_bandwidth(level.working_set, threads, seconds);
    roof.eigen_sum = eigen_sum_bandwidth(level.working_set, threads, seconds);
    // Three arrays in the same working set as the read's one.
    roof.triad = triad_bandwidth(level.working_set / 3, threads, seconds);
    roofs.levels.push_back(roof);
  }
  roofs.peak_double = peak_flops_double(threads, seconds);
  roofs.peak_float = peak_flops_float(threads, seconds);
  return roofs;
}

const LevelRoof& fitting_level(const Roofs& roofs, double working_set) {
  const double per_thread = working_set / std::max(roofs.threads, 1);
  for (const LevelRoof& roof : roofs.levels)
    if (roof.level.capacity > 0 && per_thread <= double(roof.level.capacity)) return roof;
  return roofs.levels.back();
}

double bound_seconds(const Roofs& roofs, const PhaseWork& work) {
  const double memory = work.bytes / fitting_level(roofs, work.working_set).read;
  const double arithmetic =
      work.flops_double / roofs.peak_double + work.flops_float / roofs.peak_float;
  return std::max(memory, arithmetic);
}

}  // namespace fem::roofline
