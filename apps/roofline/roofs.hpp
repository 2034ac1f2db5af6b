// The machine's roofs at one thread count, and the time they allow a phase's work.
#pragma once

#include <string>
#include <vector>

#include "apps/roofline/bandwidth.hpp"
#include "apps/roofline/likwid.hpp"
#include "apps/roofline/peak.hpp"
#include "chapters/work.hpp"

namespace fem::roofline {

struct LevelRoof {
  MemoryLevel level;
  double read = 0.0;       // bytes/s: the roof (read_bandwidth)
  double write = 0.0;      // bytes/s: the write roof (write_bandwidth): stores that allocate
  double update = 0.0;     // bytes/s read and written back (update_bandwidth)
  double zero = 0.0;       // bytes/s zeroed by compose's loop (zero_bandwidth)
  double eigen_sum = 0.0;  // bytes/s: the second measurement (eigen_sum_bandwidth)
  double triad = 0.0;      // bytes/s: STREAM's triad as STREAM counts it
  // likwid-bench's load, store and update at the same sizes (none of its kernels stores
  // zeros: the zeroing roof has no check of its own).
  LikwidRate likwid_read, likwid_write, likwid_update;

  // Seconds a written byte costs where the pass read its line first, after the read: an update
  // of n bytes takes 2n / update, of which n / read are its reads (0 where the update runs at
  // twice the read roof or more: the write-back hidden under the reads).
  double written_back_seconds() const;
};

struct Roofs {
  int threads = 1;
  std::vector<LevelRoof> levels;               // innermost first, memory last
  double peak_double = 0.0, peak_float = 0.0;  // flops/s
  LikwidRate likwid_peak;                      // likwid-bench's double multiply-add peak
  double clock = 0.0;                          // cycles/s, measured_clock()
  // The cores' own limits at that clock: kLoadsPerCycle packet loads and kFmasPerCycle packet
  // multiply-adds per cycle per thread.
  double core_loads = 0.0, core_flops = 0.0;  // bytes/s, flops/s
  double barrier_s = 0.0, region_s = 0.0;     // one barrier, one parallel region (sync_cost)
};

// Two loads and two multiply-adds issued per cycle: the x86 cores since Haswell and Zen 2
// (Intel's and AMD's optimization manuals); a core with fewer is below its limit, not over.
constexpr int kLoadsPerCycle = 2, kFmasPerCycle = 2;

// Every roof at `threads` threads, each kernel run for about `seconds`, with likwid-bench's
// at the same sizes where `likwid` (and where it is installed). A bandwidth roof and its check
// are sampled alike: one timing of ours and one run of likwid-bench's, back to back and at
// least kLikwidRunSeconds each, in each of kRoofRounds rounds, the best of each kept.
constexpr int kRoofRounds = 5;
Roofs measure_roofs(const std::vector<CacheLevel>& caches, int threads, double seconds,
                    bool likwid);

// The innermost level that holds the working set per thread (MemoryLevel::holds): a shared
// level measured on N bytes a thread holds no more than N (the size the system reports may be
// a virtual machine's, far above what the host gives it), a private one its capacity (a bound
// that charged a core's own cache at an outer level's roof would be no bound: chapter 11's
// compose at two threads, 0.9 MiB a thread in a 1 MiB L2 measured on 384 KiB, ran at 107% of
// the L3 roofs); memory above the largest. memory_seconds charges the share of a working set
// that the level inside could hold at that level's roofs, the rest at this one's.
const LevelRoof& fitting_level(const Roofs& roofs, double working_set);

// The levels a phase's working set fits: its parts' ("L2+L3"), innermost first.
std::string fitting_levels(const Roofs& roofs, const PhaseWork& work);

// The time the roofs allow a phase's bytes and flops (its bound adds its waiting, held_by):
// at the roofs of the level its working set fits, its bytes read at the read roof, its
// allocating writes (bytes_allocated) at the write roof (whose stores allocate their lines as
// those do), its zeroed bytes at the zeroing roof, and its other written bytes, to lines it
// read first, at written_back_seconds() each; or its flops at the peak (double and float
// flops each at their own), the longer. A phase made of parts: the sum of each part's bytes
// at the roofs of the level its own working set fits (they run one after another), or all its
// flops at the peak.
double bound_seconds(const Roofs& roofs, const PhaseWork& work);
// Its two parts: the bytes' time and the flops' time.
double memory_seconds(const Roofs& roofs, const PhaseWork& work);
double arithmetic_seconds(const Roofs& roofs, const PhaseWork& work);

// The least time `regions` parallel regions and `barriers` barriers take at their measured
// costs (barrier_s, region_s) on a team of `team` threads: none on one thread (nothing to
// wait for; the adaptive team's other choice), the roofs' costs on any other team (a stepper
// that does not say its team, 0, runs on the roofs' count).
double waiting_seconds(const Roofs& roofs, int team, double regions, double barriers);

// Which of a phase's three least times holds it, the largest: "bytes", "flops" or "waiting".
// The phase's bound is max(bytes, flops) + waiting: the bytes and the flops overlap (a core
// computes while its loads are in flight), a barrier waits for both to end on every thread.
const char* held_by(double memory_s, double arithmetic_s, double waiting_s);

}  // namespace fem::roofline
