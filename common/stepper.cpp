#include "common/stepper.hpp"

#include <iostream>

namespace fem {

long long (*allocation_count_hook)() = nullptr;

void report_if_not_converged(const StepProfile& profile, const SolverSettings& settings,
                             const char* chapter, bool& already_warned) {
  if (profile.converged || already_warned) return;
  already_warned = true;
  std::cerr << "warning: " << chapter << ": the linear solve stopped at the iteration cap ("
            << settings.max_iterations << ") with relative residual " << profile.relative_residual
            << " > tolerance " << settings.tolerance
            << " (reported once; see StepProfile::converged for every step)\n";
}

}  // namespace fem
