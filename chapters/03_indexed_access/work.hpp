// This chapter's work per phase (chapters/work.hpp: the model): its compressed matrices
// counted as the first chapter's data model counts them, the constraints as the sparse products S A
// S^T into a second matrix.
#pragma once

#include <vector>

#include "chapters/03_indexed_access/stepper.hpp"
#include "chapters/work.hpp"

namespace fem::ch03 {

std::vector<PhaseWork> count_work(const IndexedAccessStepper& stepper, const Scene& scene,
                                  const WorkCounts& counts);

}  // namespace fem::ch03
