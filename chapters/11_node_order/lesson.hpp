// The measurement behind chapter 11's lesson table: `fem_lessons node-order`, the same scene
// in each node order (the file's, RCM, Morton, and gmsh's own when fem-tools runs renumber-meshes
// wrote them): bandwidth, envelope, element spread, colours, and the time of the element pass,
// of one SpMV and of one V-cycle.
#pragma once

#include <vector>

#include "common/lesson.hpp"

namespace fem::ch11 {

std::vector<Lesson> lessons();

}  // namespace fem::ch11
