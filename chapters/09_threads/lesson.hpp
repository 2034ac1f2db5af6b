// The measurement behind chapter 09's lesson table: `fem_lessons threads-element`, the fused
// element pass in parallel by colouring and by per-node gather, on one thread and on all of them.
#pragma once

#include <vector>

#include "common/lesson.hpp"

namespace fem::ch09 {

std::vector<Lesson> lessons();

}  // namespace fem::ch09
