// This chapter's work per phase (chapters/work.hpp: the model): its compressed matrices
// counted as the first chapter's data model counts them, the constraints in place (the constrained
// rows and columns only).
#pragma once

#include <vector>

#include "chapters/06_custom_pcg/stepper.hpp"
#include "chapters/work.hpp"

namespace fem::ch06 {

std::vector<PhaseWork> count_work(const CustomPcgStepper& stepper, const Scene& scene,
                                  const WorkCounts& counts);

}  // namespace fem::ch06
