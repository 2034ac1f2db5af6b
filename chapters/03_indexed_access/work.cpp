#include "chapters/03_indexed_access/work.hpp"

#include "chapters/01_naive/work.hpp"

namespace fem::ch03 {

std::vector<PhaseWork> count_work(const IndexedAccessStepper& stepper, const Scene& scene,
                                  const WorkCounts& counts) {
  return ch01::compressed_work(stepper.dfdx(), stepper.system_matrix(), scene, counts, false);
}

}  // namespace fem::ch03
