#include "chapters/05_inplace_constraints/work.hpp"

#include "chapters/01_naive/work.hpp"

namespace fem::ch05 {

std::vector<PhaseWork> count_work(const InplaceConstraintsStepper& stepper, const Scene& scene,
                                  const WorkCounts& counts) {
  return ch01::compressed_work(stepper.dfdx(), stepper.system_matrix(), scene, counts, true);
}

}  // namespace fem::ch05
