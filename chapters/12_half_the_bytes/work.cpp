#include "chapters/12_half_the_bytes/work.hpp"

namespace fem::ch12 {

ch08::ElementWork element_work(const BatchedElementPass&, const ch08::WorkInput& in) {
  return ch08::fused_pass_work(in);
}

ExecutedWork element_counters(const BatchedElementPass& part, double elements) {
  return batch_counters(part.batched_elements(), elements);
}

ExecutedWork batch_counters(const BatchedElements& e, double elements) {
  ExecutedWork w;
  w.steps = elements > 0 ? double(e.total_rotations()) / elements : 0.0;
  w.rotations = double(e.total_rotations());
  w.rotation_iterations = double(e.total_newton_iterations());
  w.rotation_fallbacks = double(e.total_fallbacks());
  return w;
}

}  // namespace fem::ch12
