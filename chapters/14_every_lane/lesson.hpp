// The measurement behind chapter 14's lesson table: `fem_lessons every-lane`, the finest
// level's float kernels of the V-cycle alone, on the data of a few steps of this chapter's
// stepper (in cache where the level fits): chapter 12's (a block's column in 4 lanes), this
// chapter's pair lanes, and the row pairs (two rows' pairs in 512 bits), at 1 and 2 threads;
// then one whole V-cycle with each finest level.
#pragma once

#include <vector>

#include "common/lesson.hpp"

namespace fem::ch14 {

std::vector<Lesson> lessons();

}  // namespace fem::ch14
