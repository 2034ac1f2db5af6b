// The measurement behind chapter 03's lesson table: `fem_lessons dfdx-fill`, df/dx construction by
// coeffRef, by setFromTriplets, by the table.
#pragma once

#include <vector>

#include "common/lesson.hpp"

namespace fem::ch03 {

std::vector<Lesson> lessons();

}  // namespace fem::ch03
