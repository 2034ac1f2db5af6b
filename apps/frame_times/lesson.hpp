// The library's frame times (docs/library.md): `fem_lessons frame-times` steps one body with
// the library (femcourse::Body, the default chapter) as an interactive app does, a few
// thousand steps, and reports the median, the 99th percentile and the longest step: on one
// and two threads, on a quiet machine and with another process spinning on one core, with
// plain steps and with a node dragged every step (its constraint changed in place).
#pragma once

#include <vector>

#include "common/lesson.hpp"

namespace fem::frame_times {

std::vector<Lesson> lessons();

}  // namespace fem::frame_times
