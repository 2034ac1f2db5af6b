// This chapter's work per phase (chapters/work.hpp: the model): the data of the fused pass
// and the block-Jacobi PCG as before; its counters say, besides the element pass's, the team
// each step ran on (the adaptive team may take one thread where more were given).
#pragma once

#include "chapters/09_threads/stepper.hpp"
#include "chapters/work.hpp"

namespace fem::ch09 {

ExecutedWork executed_work(const ThreadsStepper& stepper);

}  // namespace fem::ch09
