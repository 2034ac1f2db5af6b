// The roofs' independent check: the same working sets and thread counts measured by
// likwid-bench (Treibig, Hager & Wellein, "LIKWID: a lightweight performance-oriented tool
// suite for x86 multicore environments", ICPPW 2010; Debian's `likwid`), whose kernels are
// hand-written assembly: a roof of ours far below its number is a kernel of ours that does not
// reach the hardware; far above it, a timing that credits more than the machine sustains.
#pragma once

#include <cstddef>
#include <string>

#include "apps/roofline/best_rate.hpp"

namespace fem::roofline {

// What likwid-bench measured, or why it did not.
struct LikwidRate {
  double rate = 0.0;  // bytes/s (load, store kernels) or flops/s (peakflops); 0 if not run
  std::string kernel;
  std::string note;  // empty if it ran; else why not ("not installed", its error)
};

// load, store, update (a load and a store back of each element: 16 bytes an element, as our
// update roof counts them) and the double multiply-add peak.
enum class LikwidKernel { load, store, update, peak };

// A likwid-bench run lasts at least this long: its short runs at two threads report less than
// its threads do (on the 2-core Zen 5 VM, store_avx512 in L1 at two threads: 218-340 GB/s in
// runs of 0.1-0.5 s, 404-498 in runs of 1.5 s, against 218-265 at one thread; a pinned,
// barrier-timed loop of the same stores 518-545 at two), so that a check made of short runs
// measured its own start, not the cache.
constexpr double kLikwidRunSeconds = 1.0;

// likwid-bench's `kernel` at the build's vector width (load_avx512 or load_avx, ...) in
// `threads` processes of one thread at once, each pinned to its own CPU (the ones this process
// may use, in order) on its own `bytes_per_thread` (-W), their rates summed; the best of `runs`
// runs of `run_seconds` each, or
// kLikwidRunSeconds if longer (measure_roofs: one in each of its rounds, right after our
// roof's timing of the same length). A run's length is set by its
// iterations (-i), from `expected` (our own roof's rate, in the kernel's units): likwid-bench's
// -s takes whole seconds and reads "0.5" as none, and then runs the least it runs, ten
// iterations, too short a time for any clock.
LikwidRate likwid_bench(LikwidKernel kernel, std::size_t bytes_per_thread, int threads,
                        double run_seconds, double expected, int runs = kRoofTimings);

// The command line of one of likwid_bench's runs (its iterations from `expected`).
std::string likwid_command(LikwidKernel kernel, std::size_t bytes_per_thread, int threads,
                           double run_seconds, double expected);

// The core's own limit at the clock measured on the spot: `per_cycle` loads (or multiply-
// adds) of one packet each per cycle, times the packet's bytes (or its 2 flops per lane),
// times the clock, times the threads. measured_clock() times a chain of dependent integer
// additions, one per cycle on every x86 and ARM core of the last decade.
double measured_clock();

}  // namespace fem::roofline
