// This chapter's work per phase (chapters/work.hpp: the model), and the counts of its data
// model for the chapters that keep it: the fused element pass (the elements' shapes and
// rotations, no df/dx), what is left of the composition, and the PCG on the block matrix.
#pragma once

#include <vector>

#include "chapters/01_naive/work.hpp"
#include "chapters/08_element_kernels/stepper.hpp"
#include "chapters/work.hpp"

namespace fem::ch08 {

std::vector<PhaseWork> count_work(const ElementKernelsStepper& stepper, const Scene& scene,
                                  const WorkCounts& counts);
// The element pass's counters: steps, rotations, Newton's iterations and fallbacks.
ExecutedWork executed_work(const ElementKernelsStepper& stepper);

// The fused pass and the composition, the block constraints, and the PCG with
// `preconditioner`, whose set-up per solve reads `prepare_read` bytes and writes
// `prepare_written` (fresh lines).
std::vector<PhaseWork> fused_work(const ElementKernelsStepper& stepper, const Scene& scene,
                                  const WorkCounts& counts, const PhaseWork& preconditioner,
                                  double prepare_read, double prepare_written);

// Flops of one element of the fused pass besides its rotation, term by term from the
// kernels' formulas (element_kernels.cpp), and of the rotation: per Newton iteration and
// once per rotation Newton found (its normalization and its matrix).
double fused_element_flops();
double newton_iteration_flops();
double newton_finish_flops();
// The rotations' flops of one step: from the iterations counted during the steps
// (counts.per_step), or at least one iteration per element where nothing was counted.
double rotation_flops(const WorkCounts& counts, double elements);

}  // namespace fem::ch08
