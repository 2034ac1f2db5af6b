// The measurement behind chapter 12's lesson table: `fem_lessons half-the-bytes`, the same
// scene with chapter 11's V-cycle in double and chapter 12's on float numbers (in float, and
// widened to double): the bytes of the V-cycle's numbers, the time of one V-cycle, and the
// iterations at the default tolerance and at a tight one.
#pragma once

#include <vector>

#include "common/lesson.hpp"

namespace fem::ch12 {

std::vector<Lesson> lessons();

}  // namespace fem::ch12
