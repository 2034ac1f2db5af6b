// This chapter's parts' work (chapters/08_element_kernels/work.hpp: counted part by part): the
// fused pass and the block-Jacobi PCG count as chapter 08's, on every thread; its team says
// which team each step ran on (the adaptive team may take one thread where more were given).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "chapters/08_element_kernels/work.hpp"
#include "chapters/09_threads/parts.hpp"
#include "chapters/09_threads/threaded_elements.hpp"

namespace fem::ch09 {

ch08::ElementWork element_work(const ThreadedElements& part, const ch08::WorkInput& in);
ch08::PreconditionerWork preconditioner_work(const JacobiOnChunks& part, const ch08::WorkInput& in);
PhaseWork solver_work(const ParallelPcgSolver& part, const ch08::WorkInput& in,
                      const ch08::PreconditionerWork& preconditioner);
ExecutedWork element_counters(const ThreadedElements& part, double elements);
double team_size(const TeamOfThreads& team);

// The PCG's own kernels alone, which its count takes as one part ("pcg", ch01::pcg_work): the
// kernels its loops call (parallel_pcg.hpp), the product through the recipe's product part,
// once per pass each; and block Jacobi s = D^-1 r (the "preconditioner" part).
std::vector<PartKernel> solver_kernels(ParallelPcgSolver& part, const ch08::KernelInput& in);
std::vector<PartKernel> preconditioner_kernels(JacobiOnChunks& part, const ch08::KernelInput& in);
// A kernel of `part` (a part of the solve's count), run `calls` times a step.
PartKernel part_kernel(const std::string& name, const std::string& part, const PhaseWork& work,
                       double calls, std::function<void()> run);

}  // namespace fem::ch09
