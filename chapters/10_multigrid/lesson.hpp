// The measurement behind chapter 10's lesson table: `fem_lessons multigrid`, the hierarchy,
// the iterations, the cost of prepare and of one V-cycle, and PCG against block Jacobi and
// Eigen's IncompleteCholesky on the last system (and the system exported for PyAMG).
#pragma once

#include <vector>

#include "chapters/10_multigrid/stepper.hpp"
#include "common/cli.hpp"
#include "common/lesson.hpp"

namespace fem::ch10 {

std::vector<Lesson> lessons();

}  // namespace fem::ch10
