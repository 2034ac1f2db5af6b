// This chapter's work per phase (chapters/work.hpp: the model): the V-cycle's levels in
// float, its arithmetic in float or in double as the stepper was asked.
#pragma once

#include <vector>

#include "chapters/12_half_the_bytes/stepper.hpp"
#include "chapters/work.hpp"

namespace fem::ch12 {

std::vector<PhaseWork> count_work(const HalfBytesStepper& stepper, const Scene& scene,
                                  const WorkCounts& counts);
// The batched element pass's counters: rotations, Newton's iterations (every lane of a batch
// runs the batch's), fallbacks.
ExecutedWork executed_work(const HalfBytesStepper& stepper);

}  // namespace fem::ch12
