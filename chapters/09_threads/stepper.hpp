// Chapter 09: every core, deterministically. The same step as before, on all the threads
// OpenMP is given (OMP_NUM_THREADS or --threads): the element pass without races or
// atomics (threaded_elements.hpp), the block SpMV over rows, the PCG's vector operations fused
// so that an iteration waits at three barriers (parallel_pcg.hpp), and every sum over the mesh
// taken over a FIXED partition in a fixed order, so that the state after any number of steps
// is the same to the last bit for any thread count.
#pragma once

// The recipe it builds on, and the files of the parts it adds.
#include "chapters/08_element_kernels/stepper.hpp"
#include "chapters/09_threads/parts.hpp"
#include "chapters/09_threads/threaded_elements.hpp"

namespace fem::ch09 {

struct Threads {
  using BuildsOn = ch08::ElementKernels;
  using Order = ch08::MeshOrder;
  using Team = ch09::TeamOfThreads;
  using Elements = ch09::ThreadedElements;
  using Guess = ch08::WarmStart;
  using Product = ch08::AssembledProduct;
  using Preconditioner = ch09::JacobiOnChunks;
  using Solver = ch09::ParallelPcgSolver;
};

using ThreadsStepper = ch08::StepOf<Threads>;

// The stepper's parameters with its element pass's parallelism (the lesson measures both).
inline ThreadsStepper::Params parallelism(ElementParallelism how) {
  ThreadsStepper::Params params;
  params.elements.parallelism = how;
  return params;
}

}  // namespace fem::ch09
