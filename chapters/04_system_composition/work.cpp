#include "chapters/04_system_composition/work.hpp"

#include "chapters/01_naive/work.hpp"

namespace fem::ch04 {

std::vector<PhaseWork> count_work(const SystemCompositionStepper& stepper, const Scene& scene,
                                  const WorkCounts& counts) {
  return ch01::compressed_work(stepper.dfdx(), stepper.system_matrix(), scene, counts, false);
}

}  // namespace fem::ch04
