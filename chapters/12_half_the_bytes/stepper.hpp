// Chapter 12: half the bytes. Chapter 11's step with the V-cycle's numbers stored in float
// (reduced_v_cycle.hpp) inside chapter 09's double-precision PCG: the preconditioner streams
// half the bytes, and the solve still stops at the same tolerance on the same residual. And
// the element pass across elements (element_batch.hpp): a batch of elements per vector
// register, where Eigen's fixed-size 3x3 types leave most lanes empty.
#pragma once

// The recipe it builds on, and the files of the parts it adds.
#include "chapters/11_node_order/stepper.hpp"
#include "chapters/12_half_the_bytes/parts.hpp"

namespace fem::ch12 {

struct HalfTheBytes {
  using BuildsOn = ch11::NodeOrderRecipe;
  using Order = ch11::RenumberedNodes;
  using Team = ch09::TeamOfThreads;
  using Elements = ch12::BatchedElementPass;
  using Guess = ch10::Extrapolation;
  using Product = ch08::AssembledProduct;
  using Preconditioner = ch12::ReducedMultigrid<float>;
  using Solver = ch09::ParallelPcgSolver;
};

using HalfBytesStepper = ch08::StepOf<HalfTheBytes>;

}  // namespace fem::ch12
