#include "apps/roofline/roofs.hpp"

#include <algorithm>

#include "apps/roofline/sync_cost.hpp"
#include "common/lesson.hpp"

namespace fem::roofline {

namespace {

// The double peak and its check sampled as the levels are, in rounds: one of each, back to
// back. Timed one after the other, on the 2-vCPU Xeon ours read 84 GFlop/s at two threads (one
// thread's rate: the two vCPUs on one core) and likwid-bench's, run after it, 140.
void measure_peak(Roofs& roofs, int threads, double seconds, bool likwid) {
  const double round_s =
      likwid ? std::max(seconds / kRoofRounds, kLikwidRunSeconds) : seconds / kRoofRounds;
  for (int round = 0; round < kRoofRounds; ++round) {
    const double peak = peak_flops_double(threads, round_s, likwid ? 1 : kRoofTimings);
    roofs.peak_double = std::max(roofs.peak_double, peak);
    if (!likwid) continue;
    const LikwidRate r = likwid_bench(LikwidKernel::peak, 16 << 10, threads, round_s, peak, 1);
    if (r.rate > roofs.likwid_peak.rate || roofs.likwid_peak.kernel.empty()) roofs.likwid_peak = r;
  }
}

}  // namespace

Roofs measure_roofs(const std::vector<CacheLevel>& caches, int threads, double seconds,
                    bool likwid) {
  Roofs roofs;
  roofs.threads = threads;
  for (const MemoryLevel& level : memory_levels(caches, threads)) {
    progress("roofline: " + level.name + " bandwidth at " + std::to_string(threads) + " thread(s)");
    LevelRoof roof;
    roof.level = level;
    const std::size_t bytes = level.working_set;
    // Each roof and its likwid-bench check sampled alike: one timing of ours and one run of
    // likwid-bench's, back to back and as long (kLikwidRunSeconds), in each of kRoofRounds
    // rounds, the best of the rounds kept. A virtual machine's host moves a level's rate from
    // one minute to the next, ours and likwid-bench's together (the 2-core Zen 5 VM's memory
    // store at two threads: 30 to 60 GB/s); a check timed for longer than its roof compared
    // other minutes (ours at 89% of likwid-bench's in one sitting), and a roof made of more,
    // shorter timings than its check caught a quieter moment (115% in the next).
    const double round_s =
        likwid ? std::max(seconds / kRoofRounds, kLikwidRunSeconds) : seconds / kRoofRounds;
    const int timings = likwid ? 1 : kRoofTimings;
    const auto check = [&](LikwidRate& best, LikwidKernel kernel, double expected) {
      if (!likwid) return;
      const LikwidRate r = likwid_bench(kernel, bytes, threads, round_s, expected, 1);
      if (r.rate > best.rate || best.kernel.empty()) best = r;
    };
    for (int round = 0; round < kRoofRounds; ++round) {
      const double read = read_bandwidth(bytes, threads, round_s, timings);
      check(roof.likwid_read, LikwidKernel::load, read);
      const double write = write_bandwidth(bytes, threads, round_s, timings);
      check(roof.likwid_write, LikwidKernel::store, write);
      const double update = update_bandwidth(bytes, threads, round_s, timings);
      check(roof.likwid_update, LikwidKernel::update, update);
      roof.read = std::max(roof.read, read);
      roof.write = std::max(roof.write, write);
      roof.update = std::max(roof.update, update);
      roof.zero = std::max(roof.zero, zero_bandwidth(bytes, threads, seconds / kRoofRounds));
      // The read's second measurement in the same rounds, sampled as the read is: once after
      // the rounds it measured another minute (54% apart from memory's read at two threads).
      roof.eigen_sum =
          std::max(roof.eigen_sum, eigen_sum_bandwidth(bytes, threads, round_s, timings));
    }
    // Three arrays in the same working set as the read's one.
    roof.triad = triad_bandwidth(bytes / 3, threads, seconds);
    roofs.levels.push_back(roof);
  }
  measure_peak(roofs, threads, seconds, likwid);
  roofs.peak_float = peak_flops_float(threads, seconds);
  roofs.clock = measured_clock();
  roofs.barrier_s = barrier_seconds(threads);
  roofs.region_s = region_seconds(threads);
  roofs.core_loads = kLoadsPerCycle * double_lanes() * 8.0 * roofs.clock * threads;
  roofs.core_flops = kFmasPerCycle * double_lanes() * 2.0 * roofs.clock * threads;
  return roofs;
}

double LevelRoof::written_back_seconds() const { return std::max(0.0, 2.0 / update - 1.0 / read); }

const LevelRoof& fitting_level(const Roofs& roofs, double working_set) {
  const double per_thread = working_set / std::max(roofs.threads, 1);
  for (const LevelRoof& roof : roofs.levels)
    if (roof.level.capacity > 0 && per_thread <= double(roof.level.holds())) return roof;
  return roofs.levels.back();
}

namespace {

// The work's bytes at one level's roofs.
double seconds_at(const LevelRoof& level, const PhaseWork& work) {
  // The written bytes that are neither zeroed nor allocating: stores to lines read first.
  const double written_back =
      std::max(0.0, work.bytes_written - work.bytes_allocated - work.bytes_zeroed);
  return work.bytes_read / level.read + work.bytes_allocated / level.write +
         work.bytes_zeroed / level.zero + written_back * level.written_back_seconds();
}

}  // namespace

double memory_seconds(const Roofs& roofs, const PhaseWork& work) {
  if (!work.parts.empty()) {
    double seconds = 0.0;
    for (const PhaseWork& part : work.parts) seconds += memory_seconds(roofs, part);
    return seconds;
  }
  const LevelRoof& level = fitting_level(roofs, work.working_set);
  const double outer = seconds_at(level, work);
  if (&level == &roofs.levels.front()) return outer;
  // The level inside still holds part of a working set too large for it: at best (the
  // replacement a bound must allow) that part is served from there on every pass and only the
  // rest from this level. Without it a set just above a private cache ran faster than its
  // bound (chapter 12's compose at one thread, 1.8 MB beside a 1 MiB L2: 105% of the L3 roofs).
  const LevelRoof& inner = *(&level - 1);
  const double per_thread = work.working_set / std::max(roofs.threads, 1);
  const double share =
      per_thread > 0.0 ? std::min(1.0, double(inner.level.holds()) / per_thread) : 0.0;
  return share * seconds_at(inner, work) + (1.0 - share) * outer;
}

std::string fitting_levels(const Roofs& roofs, const PhaseWork& work) {
  if (work.parts.empty()) return fitting_level(roofs, work.working_set).level.name;
  std::string names;
  for (const LevelRoof& level : roofs.levels)
    for (const PhaseWork& part : work.parts)
      if (&fitting_level(roofs, part.working_set) == &level) {
        names += (names.empty() ? "" : "+") + level.level.name;
        break;
      }
  return names;
}

double arithmetic_seconds(const Roofs& roofs, const PhaseWork& work) {
  return work.flops_double / roofs.peak_double + work.flops_float / roofs.peak_float;
}

double bound_seconds(const Roofs& roofs, const PhaseWork& work) {
  return std::max(memory_seconds(roofs, work), arithmetic_seconds(roofs, work));
}

double waiting_seconds(const Roofs& roofs, int team, double regions, double barriers) {
  if (team == 1) return 0.0;
  return regions * roofs.region_s + barriers * roofs.barrier_s;
}

const char* held_by(double memory_s, double arithmetic_s, double waiting_s) {
  if (waiting_s > std::max(memory_s, arithmetic_s)) return "waiting";
  return memory_s >= arithmetic_s ? "bytes" : "flops";
}

}  // namespace fem::roofline
