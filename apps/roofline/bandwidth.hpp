// The roofline's bandwidth roofs: how many bytes per second this machine reads from, and writes
// to, each level of its memory hierarchy, on one thread and on a team: the cache-aware roofline
// (Ilic, Pratas & Sousa, "Cache-aware Roofline model: upgrading the loft", IEEE CAL 13(1), 2014),
// one roof per level, beside the DRAM roof of Williams, Waterman & Patterson (CACM 52(4), 2009).
// Measured, not looked up: the vendor's number is a bus's width times its clock, which no loop
// reaches. STREAM's triad (McCalpin 1995) is shown beside them.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "apps/roofline/best_rate.hpp"
#include "common/machine_record.hpp"

namespace fem::roofline {

// The data and unified caches of machine_record(), innermost first; fallback_levels() where
// the system does not say.
std::vector<CacheLevel> cache_levels();
// 32 KiB, 1 MiB, 32 MiB: a guess that stands in where cache_levels() is empty.
std::vector<CacheLevel> fallback_levels();

// Where the data of a roof lives: a cache level, or memory (level 0 after the caches).
struct MemoryLevel {
  std::string name;             // "L1", ..., "memory"
  std::size_t capacity = 0;     // bytes one thread may use and still fit (0: memory, unbounded)
  std::size_t working_set = 0;  // the array each thread reads to measure it
  bool shared = false;          // a cache shared by cores (its reported size may be a VM's)

  // The most bytes a thread's working set may have and be placed here: a private cache's
  // capacity (its size is the core's own, true also in a virtual machine), a shared cache's
  // measured working set (a VM may report its host's whole last-level cache: on one, 480 MiB
  // held 184-209 MiB working sets at a roof measured on 8 MiB a thread).
  std::size_t holds() const { return shared ? working_set : capacity; }
};

// The levels with the working set each measurement uses: half of a private cache (so that
// the code and the stack do not push the array out) but at most eight times the level inside
// it, half of a shared cache split between `threads` but at most four times the share of the
// level inside it, and memory at four times the largest cache. A working set is placed in a level
// only up to the size its roofs were measured on (fitting_level, roofs.hpp).
std::vector<MemoryLevel> memory_levels(const std::vector<CacheLevel>& caches, int threads);

// The best read bandwidth (bytes/s) of `threads` threads, each loading its own array of
// `bytes` over and over for about `seconds`: the best of `timings` timed repetitions, since a
// roof is what the machine can do, and a slower repetition only says something else ran.
double read_bandwidth(std::size_t bytes, int threads, double seconds, int timings = kRoofTimings);

// The best write bandwidth (bytes stored per second): every thread fills its own array of
// `bytes` with packet stores. Where the array is not in the level (memory), each store's
// line is first read (write-allocate): the roof prices that read with the store.
double write_bandwidth(std::size_t bytes, int threads, double seconds, int timings = kRoofTimings);

// The best update bandwidth (bytes read and written back per second, as likwid-bench's update
// kernels count them): every thread loads each packet of its own array of `bytes` and stores
// it back to the same line, which the pass has just read. The store allocates nothing: its
// line is in the core's cache already, and leaves it written back (dirty) only.
double update_bandwidth(std::size_t bytes, int threads, double seconds, int timings = kRoofTimings);

// The best zeroing bandwidth (bytes zeroed per second): every thread zeroes its own array of
// `bytes` of 3x3 blocks block by block (Matrix3d::setZero), as compose zeroes A from chapter
// 08 on: the same loop, compiled as the chapters' is (vector stores of whole lines, or a call
// to memset where the compiler makes one). Not the write kernel's price: a core may store
// zeros faster than other values (an AMD Zen 5 VM: 39.5 against 34.0 GB/s to memory).
double zero_bandwidth(std::size_t bytes, int threads, double seconds);

// The packets the read kernel loads per stride, each kept by an empty asm statement and not
// summed, for the lesson's text.
int read_packets();

// The same read, by another kernel: Eigen's own sum (DenseBase::sum, Eigen/src/Core/Redux.h)
// of a VectorXd per thread. The roof's second, independent measurement.
double eigen_sum_bandwidth(std::size_t bytes, int threads, double seconds,
                           int timings = kRoofTimings);

// STREAM's triad a = b + s c on three arrays of `bytes` each, counted as STREAM counts it
// (24 bytes per element: two reads, one write; the cache line the write first reads is not
// counted). What STREAM would report as the machine's bandwidth.
double triad_bandwidth(std::size_t bytes, int threads, double seconds);

}  // namespace fem::roofline
