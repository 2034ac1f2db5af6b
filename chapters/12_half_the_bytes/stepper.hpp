// Chapter 12: half the bytes. Chapter 11's step with the V-cycle's numbers stored in float
// (reduced_v_cycle.hpp) inside chapter 09's double-precision PCG: the preconditioner streams
// half the bytes, and the solve still stops at the same tolerance on the same residual. And
// the element pass across elements (element_batch.hpp): a batch of elements per vector
// register, where Eigen's fixed-size 3x3 types leave most lanes empty.
#pragma once

#include <memory>

#include "chapters/11_node_order/stepper.hpp"
#include "chapters/12_half_the_bytes/element_batch.hpp"
#include "chapters/12_half_the_bytes/reduced_v_cycle.hpp"

namespace fem::ch12 {

class HalfBytesStepper : public ch11::NodeOrderStepper {
 public:
  // single: the V-cycle in float on float numbers (the default); double_on_float: the same
  // float numbers, widened to double in registers (the lesson measures both).
  HalfBytesStepper(const Scene& scene, const SolverSettings& settings,
                   Arithmetic arithmetic = Arithmetic::single,
                   const ch10::MultigridStepperSettings& multigrid = {});

  Arithmetic arithmetic() const { return arithmetic_; }
  const BatchedElements& batched_elements() const { return batched_; }
  // The preconditioner (the lesson times it alone; outside a team it runs on one thread).
  ch09::Preconditioner& v_cycle() { return *v_cycle_; }

 private:
  // Chapter 09's colouring (chapter 11's slabs), each group in batches of kLanes elements.
  void element_pass(const State& state) override;

  Arithmetic arithmetic_;
  BatchedElements batched_;
  std::unique_ptr<ch09::Preconditioner> v_cycle_;  // reads multigrid(): declared after it
};

}  // namespace fem::ch12
