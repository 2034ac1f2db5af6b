// Chapter 12: half the bytes. Chapter 11's step with the V-cycle's numbers stored in float
// (reduced_v_cycle.hpp) inside chapter 09's double-precision PCG: the preconditioner streams
// half the bytes, and the solve still stops at the same tolerance on the same residual. And
// the element pass across elements (element_batch.hpp): a batch of elements per vector
// register, where Eigen's fixed-size 3x3 types leave most lanes empty.
#pragma once

#include "chapters/08_element_kernels/step.hpp"
#include "chapters/09_threads/parts.hpp"
#include "chapters/10_multigrid/parts.hpp"
#include "chapters/11_node_order/renumbered_nodes.hpp"
#include "chapters/11_node_order/stepper.hpp"
#include "chapters/12_half_the_bytes/parts.hpp"

namespace fem::ch12 {

struct HalfTheBytes {
  using BuildsOn = ch11::NodeOrderRecipe;  // the chapter this recipe changes
  using Order = ch11::RenumberedNodes;             // chapter 11's
  using Team = ch09::TeamOfThreads;                // chapter 09's
  using Elements = BatchedElementPass;             // new: one element per lane
  using Guess = ch10::Extrapolation;               // chapter 10's
  using Preconditioner = ReducedMultigrid<float>;  // new: the V-cycle in float
  using Solver = ch09::ParallelPcgSolver;          // chapter 09's
};

using HalfBytesStepper = ch08::StepOf<HalfTheBytes>;

}  // namespace fem::ch12
