// The measurement behind chapter 04's lesson table: `fem_lessons compose`, the heap allocations of
// chapter 03's sparse sums, cause by cause.
#pragma once

#include <vector>

#include "common/lesson.hpp"

namespace fem::ch04 {

std::vector<Lesson> lessons();

}  // namespace fem::ch04
