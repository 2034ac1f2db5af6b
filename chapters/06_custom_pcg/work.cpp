#include "chapters/06_custom_pcg/work.hpp"

#include "chapters/01_naive/work.hpp"

namespace fem::ch06 {

std::vector<PhaseWork> count_work(const CustomPcgStepper& stepper, const Scene& scene,
                                  const WorkCounts& counts) {
  return ch01::compressed_work(stepper.dfdx(), stepper.system_matrix(), scene, counts, true);
}

}  // namespace fem::ch06
