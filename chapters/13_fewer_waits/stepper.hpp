// Chapter 13: fewer waits. Chapter 12's step, with its float V-cycle run in fewer parallel
// loops (fused_v_cycle.hpp) inside a PCG with one wait per reduction (single_reduction_pcg.hpp):
// every loop ends at a barrier where each thread waits for the slowest, and a loop whose work
// reads only its own rows can run inside the loop before it.
#pragma once

// The recipe it builds on, and the files of the parts it adds.
#include "chapters/12_half_the_bytes/stepper.hpp"
#include "chapters/13_fewer_waits/parts.hpp"

namespace fem::ch13 {

struct FewerWaits {
  using BuildsOn = ch12::HalfTheBytes;
  using Order = ch11::RenumberedNodes;
  using Team = ch09::TeamOfThreads;
  using Elements = ch12::BatchedElementPass;
  using Guess = ch10::Extrapolation;
  using Product = ch08::AssembledProduct;
  using Preconditioner = ch13::FusedPreconditioner;
  using Solver = ch13::SingleReductionSolver;
};

using FewerWaitsStepper = ch08::StepOf<FewerWaits>;

}  // namespace fem::ch13
