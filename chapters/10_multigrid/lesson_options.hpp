// The lesson's command line (lesson_options.cpp), private to the lesson (lesson.cpp): its
// options declared with the chapter's defaults and read back as the stepper's settings.
#pragma once

#include "chapters/10_multigrid/stepper.hpp"
#include "common/cli.hpp"

namespace fem::ch10 {

void add_multigrid_options(ArgParser& args);
// Throws UsageError for a value the options do not name (a smoother, --l1) and for settings
// the stepper refuses (check(), stepper.hpp).
MultigridStepperSettings multigrid_from_args(const ArgParser& args);

}  // namespace fem::ch10
