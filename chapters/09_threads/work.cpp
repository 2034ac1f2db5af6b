#include "chapters/09_threads/work.hpp"

#include "chapters/08_element_kernels/work.hpp"

namespace fem::ch09 {

ExecutedWork executed_work(const ThreadsStepper& stepper) {
  ExecutedWork e = ch08::executed_work(stepper);
  e.team = stepper.adaptive_team().team();
  return e;
}

}  // namespace fem::ch09
