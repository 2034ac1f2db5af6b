// Chapter 10: a solve that grows far more slowly with the mesh. Chapter 09's threaded step (the
// fused element pass, the block SpMV over fixed row chunks, sums in chunk order) with one V-cycle
// of smoothed-aggregation multigrid (multigrid.hpp) as the PCG's preconditioner in place of
// block Jacobi: the preconditioner Tamstorf, Jones & McCormick 2015 pair with their PPCG.
// The V-cycle runs on every thread of the PCG's team over fixed row blocks, with sums in a
// fixed order, so the result is still the same to the last bit for any thread count; the
// guess is extrapolated from the last solutions.
#pragma once

// The recipe it builds on, and the files of the parts it adds.
#include "chapters/09_threads/stepper.hpp"
#include "chapters/10_multigrid/parts.hpp"

namespace fem::ch10 {

struct MultigridRecipe {
  using BuildsOn = ch09::Threads;
  using Order = ch08::MeshOrder;
  using Team = ch09::TeamOfThreads;
  using Elements = ch09::ThreadedElements;
  using Guess = ch10::Extrapolation;
  using Product = ch08::AssembledProduct;
  using Preconditioner = ch10::MultigridPreconditioner;
  using Solver = ch09::ParallelPcgSolver;
};

using MultigridStepper = ch08::StepOf<MultigridRecipe>;

}  // namespace fem::ch10
