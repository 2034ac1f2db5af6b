// The measurement behind chapter 02's lesson table: `fem_lessons noalias`, heap allocations of each
// vector statement, before and after.
#pragma once

#include <vector>

#include "common/lesson.hpp"

namespace fem::ch02 {

std::vector<Lesson> lessons();

}  // namespace fem::ch02
