#include "chapters/02_noalias/work.hpp"

#include "chapters/01_naive/work.hpp"

namespace fem::ch02 {

std::vector<PhaseWork> count_work(const NoAliasStepper& stepper, const Scene& scene,
                                  const WorkCounts& counts) {
  return ch01::compressed_work(stepper.dfdx(), stepper.system_matrix(), scene, counts, false);
}

}  // namespace fem::ch02
