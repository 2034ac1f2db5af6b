// The roofline lesson, `fem_lessons roofline`: the machine's roofs measured on the spot, and
// every chapter placed under them. Not one chapter's lesson but the course's, so fem_lessons
// registers it itself; its table goes to docs/roofline.md.
#pragma once

#include <vector>

#include "common/lesson.hpp"

namespace fem::roofline {

std::vector<Lesson> lessons();

}  // namespace fem::roofline
