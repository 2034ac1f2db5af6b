// The cost of waiting: one barrier and one parallel region of a team, measured the way EPCC's
// syncbench measures them (Bull, "Measuring synchronisation and scheduling overheads in
// OpenMP", EWOMP 1999): many in a loop, the loop's time over their count, the best of several
// repetitions. A threaded step meets hundreds of both; their count times these costs is the
// time the step waits at the least, beside the time its bytes and flops take.
#pragma once

namespace fem::roofline {

// Seconds per barrier and per (empty) parallel region of `threads` threads; 0 at one thread
// (no team: nothing to wait for).
double barrier_seconds(int threads);
double region_seconds(int threads);

}  // namespace fem::roofline
