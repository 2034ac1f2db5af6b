// Chapter 11's order part (see renumbered_nodes.hpp).
#include "chapters/11_node_order/renumbered_nodes.hpp"

#include <algorithm>

namespace fem::ch11 {

RenumberedNodes::RenumberedNodes(const Scene& scene, const Params& params)
    : RenumberedNodes(scene, params.ordering, ch11::node_order(scene.mesh, params.ordering)) {}

RenumberedNodes::RenumberedNodes(const Scene& scene, Ordering ordering, NodeOrder order)
    : ordering_(ordering),
      order_(std::move(order)),
      scene_(renumbered(scene, order_, ordering != Ordering::original)),
      inner_(rest_state(scene_)),
      caller_f_ext_(3 * scene.mesh.num_nodes()) {}

int RenumberedNodes::element_group() const {
  if (ordering_ == Ordering::original) return 0;
  return std::max(16, scene_.mesh.num_tets() / kSlabs);
}

void RenumberedNodes::set_constraints(const std::vector<NodeConstraint>& constraints) {
  scene_.constraints = constraints;
  for (NodeConstraint& c : scene_.constraints) c.node = order_.new_of_old[c.node];
}

void RenumberedNodes::map_in(const State& caller) {
  // Node k of the new numbering is node old_of_new[k] of the caller's: two gathers in, two
  // scatters out, 12 doubles per node, against the thousands of bytes a node costs the step.
  const std::vector<int>& old_of_new = order_.old_of_new;
  for (std::size_t k = 0; k < old_of_new.size(); ++k) {
    inner_.x.segment<3>(3 * k) = caller.x.segment<3>(3 * old_of_new[k]);
    inner_.v.segment<3>(3 * k) = caller.v.segment<3>(3 * old_of_new[k]);
  }
}

void RenumberedNodes::map_out(State& caller) const {
  const std::vector<int>& old_of_new = order_.old_of_new;
  for (std::size_t k = 0; k < old_of_new.size(); ++k) {
    caller.x.segment<3>(3 * old_of_new[k]) = inner_.x.segment<3>(3 * k);
    caller.v.segment<3>(3 * old_of_new[k]) = inner_.v.segment<3>(3 * k);
  }
}

const std::vector<ExternalForce>& RenumberedNodes::inward(
    const std::vector<ExternalForce>& forces) {
  const int nodes = static_cast<int>(order_.new_of_old.size());
  for (const ExternalForce& f : forces)
    if (f.node < 0 || f.node >= nodes || !f.force.allFinite()) return forces;
  renamed_forces_ = forces;
  for (ExternalForce& f : renamed_forces_) f.node = order_.new_of_old[f.node];
  return renamed_forces_;
}

void RenumberedNodes::outward(const Eigen::SparseVector<double>& f_ext) {
  caller_f_ext_.setZero();
  for (Eigen::SparseVector<double>::InnerIterator it(f_ext); it; ++it)
    caller_f_ext_.coeffRef(3 * order_.old_of_new[it.index() / 3] + it.index() % 3) = it.value();
}

}  // namespace fem::ch11
