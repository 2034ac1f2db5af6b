// Chapter 11: the order of memory. Chapter 10's step, unchanged, on the mesh renumbered once
// at construction (reverse Cuthill-McKee by default, node_order.hpp), with the elements
// sorted by their nodes in the new order. The caller keeps the mesh's numbering: the state
// and the interaction forces are mapped in and out at the step's boundary.
#pragma once

#include <vector>

#include "chapters/10_multigrid/stepper.hpp"
#include "chapters/11_node_order/node_order.hpp"

namespace fem::ch11 {

class NodeOrderStepper : public ch10::MultigridStepper {
 public:
  NodeOrderStepper(const Scene& scene, const SolverSettings& settings,
                   Ordering ordering = Ordering::rcm,
                   const ch10::MultigridStepperSettings& multigrid = {});

  // The caller's state in the mesh's numbering, in and out; chapter 10's step in between.
  void step(State& state) override;
  // The forces name the mesh's nodes: renamed on the way in, and back for the accessor.
  void set_external_forces(const std::vector<ExternalForce>& forces) override;
  const Eigen::SparseVector<double>& external_forces() const override { return caller_f_ext_; }

  const NodeOrder& order() const { return order_; }
  Ordering ordering() const { return ordering_; }

 private:
  NodeOrderStepper(const Scene& scene, const SolverSettings& settings, Ordering ordering,
                   NodeOrder order, const ch10::MultigridStepperSettings& multigrid);

  static constexpr int kSlabs = 64;  // element groups of the parallel pass (stepper.cpp)
  Ordering ordering_;
  NodeOrder order_;
  State inner_;  // the state in the new numbering, kept so that a step allocates nothing
  std::vector<ExternalForce> renamed_forces_;
  Eigen::SparseVector<double> caller_f_ext_;
};

}  // namespace fem::ch11
