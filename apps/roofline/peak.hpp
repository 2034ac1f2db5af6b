// The roofline's arithmetic roof: the multiply-add rate of this machine at the vector width
// this build targets (-march=native: AVX-512, AVX2, NEON, ... whatever Eigen's packets are).
// Measured by a loop of independent multiply-adds on Eigen's packets: enough of them in flight
// to hide the instruction's latency, none waiting on memory. The vendor's peak is the same
// product (cores x FMA units x lanes x 2 flops x clock) at a clock the chip may hold only on
// one core, or only without the wide vector units busy; the measured rate is what a loop gets.
#pragma once

#include "apps/roofline/best_rate.hpp"  // kRoofTimings

namespace fem::roofline {

// Flops per second (a multiply-add counts as 2 flops) of `threads` threads, each running the
// kernel for about `seconds` in all: the best of `timings` timings, as for the bandwidths.
double peak_flops_double(int threads, double seconds, int timings = kRoofTimings);
double peak_flops_float(int threads, double seconds, int timings = kRoofTimings);

// The lanes of one packet: what "the vector width the build targets" is, in numbers.
int double_lanes();
int float_lanes();
// The independent multiply-add chains of the peak kernel, for the lesson's text.
int fma_chains();

}  // namespace fem::roofline
