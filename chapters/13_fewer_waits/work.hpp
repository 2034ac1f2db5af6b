// This chapter's parts' work (chapters/08_element_kernels/work.hpp: counted part by part): the
// fused cycle is chapter 12's float V-cycle, the same kernels in fewer loops; Chronopoulos and
// Gear's PCG streams two vectors more than chapter 09's (w = A s, and q = w + beta q by
// recurrence), for its fewer waits.
#pragma once

#include <vector>

#include "chapters/08_element_kernels/work.hpp"
#include "chapters/13_fewer_waits/parts.hpp"

namespace fem::ch13 {

ch08::PreconditionerWork preconditioner_work(const FusedPreconditioner& part,
                                             const ch08::WorkInput& in);
PhaseWork solver_work(const SingleReductionSolver& part, const ch08::WorkInput& in,
                      const ch08::PreconditionerWork& preconditioner);

// Its own kernels alone, the ones its loops call (single_reduction_pcg.hpp), on the row chunks:
// w = A s with delta = s . w through the recipe's product part, and the update p = s + b p,
// q = w + b q, y += a p, r -= a q with r . r; and the fused cycle's fine smoothing step,
// chapter 12's.
std::vector<PartKernel> solver_kernels(SingleReductionSolver& part, const ch08::KernelInput& in);
std::vector<PartKernel> preconditioner_kernels(FusedPreconditioner& part,
                                               const ch08::KernelInput& in);

}  // namespace fem::ch13
