// Chapter 11: chapter 10's step on the renumbered mesh (see stepper.hpp and node_order.hpp).
#include "chapters/11_node_order/stepper.hpp"

#include <algorithm>

namespace fem::ch11 {

NodeOrderStepper::NodeOrderStepper(const Scene& scene, const SolverSettings& settings,
                                   Ordering ordering,
                                   const ch10::MultigridStepperSettings& multigrid)
    : NodeOrderStepper(scene, settings, ordering, node_order(scene.mesh, ordering), multigrid) {}

// The order is computed once by the public constructor and passed here, so that chapter 10's
// stepper is built on the renumbered scene before this class's members exist.
NodeOrderStepper::NodeOrderStepper(const Scene& scene, const SolverSettings& settings,
                                   Ordering ordering, NodeOrder order,
                                   const ch10::MultigridStepperSettings& multigrid)
    : MultigridStepper(renumbered(scene, order, ordering != Ordering::original), settings,
                       multigrid),
      ordering_(ordering),
      order_(std::move(order)),
      inner_(rest_state(scene_)),
      caller_f_ext_(f_ext_.size()) {
  set_external_forces(scene.external_forces);
  // Chapter 09 colours groups of 16 consecutive elements, and its pass goes colour by colour:
  // every colour visits the whole mesh, so a node's blocks of A are fetched again for every
  // colour among its elements' groups (the plate: 62 colours). Sorted along the mesh,
  // consecutive elements form a slab: 64 slabs need a handful of colours (the plate: 5), and
  // the pass walks A about once. (The slabs depend on the mesh only, so the state stays the
  // same for any thread count; the test ch11_node_order.cpp counts the colours.)
  if (ordering_ != Ordering::original)
    colour_element_groups(std::max(16, scene_.mesh.num_tets() / kSlabs));
}

void NodeOrderStepper::step(State& state) {
  // Node k of the new numbering is node old_of_new[k] of the caller's: two gathers in, two
  // scatters out, 12 doubles per node, against the thousands of bytes a node costs the step.
  const std::vector<int>& old_of_new = order_.old_of_new;
  for (std::size_t k = 0; k < old_of_new.size(); ++k) {
    inner_.x.segment<3>(3 * k) = state.x.segment<3>(3 * old_of_new[k]);
    inner_.v.segment<3>(3 * k) = state.v.segment<3>(3 * old_of_new[k]);
  }
  MultigridStepper::step(inner_);
  for (std::size_t k = 0; k < old_of_new.size(); ++k) {
    state.x.segment<3>(3 * old_of_new[k]) = inner_.x.segment<3>(3 * k);
    state.v.segment<3>(3 * old_of_new[k]) = inner_.v.segment<3>(3 * k);
  }
}

void NodeOrderStepper::set_external_forces(const std::vector<ExternalForce>& forces) {
  const int nodes = static_cast<int>(order_.new_of_old.size());
  for (const ExternalForce& f : forces)  // refused in the caller's numbering, as by chapter 10
    if (f.node < 0 || f.node >= nodes || !f.force.allFinite()) Stepper::set_external_forces(forces);
  renamed_forces_ = forces;
  for (ExternalForce& f : renamed_forces_) f.node = order_.new_of_old[f.node];
  MultigridStepper::set_external_forces(renamed_forces_);
  caller_f_ext_.setZero();
  for (Eigen::SparseVector<double>::InnerIterator it(f_ext_); it; ++it)
    caller_f_ext_.coeffRef(3 * order_.old_of_new[it.index() / 3] + it.index() % 3) = it.value();
}

}  // namespace fem::ch11
