#include "chapters/12_half_the_bytes/work.hpp"

#include "chapters/09_threads/work.hpp"
#include "chapters/10_multigrid/work.hpp"

namespace fem::ch12 {

std::vector<PhaseWork> count_work(const HalfBytesStepper& stepper, const Scene& scene,
                                  const WorkCounts& counts) {
  return ch10::multigrid_work(stepper, scene, counts, sizeof(float),
                              stepper.arithmetic() == Arithmetic::single);
}

ExecutedWork executed_work(const HalfBytesStepper& stepper) {
  const BatchedElements& e = stepper.batched_elements();
  const double elements = stepper.elements().shapes().size();
  ExecutedWork w = ch09::executed_work(stepper);  // the team and the synchronizations
  w.steps = elements > 0 ? double(e.total_rotations()) / elements : 0.0;
  w.rotations = double(e.total_rotations());
  w.rotation_iterations = double(e.total_newton_iterations());
  w.rotation_fallbacks = double(e.total_fallbacks());
  return w;
}

}  // namespace fem::ch12
