// The measurement behind chapter 08's lesson table: `fem_lessons rotations`, per element, the
// rotation by JacobiSVD and by Newton (cold and warm-started), the element blocks from a stored K0
// and in closed form.
#pragma once

#include <vector>

#include "common/lesson.hpp"

namespace fem::ch08 {

std::vector<Lesson> lessons();

}  // namespace fem::ch08
