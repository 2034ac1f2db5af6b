// Chapter 11's part: the step run on the mesh renumbered once at construction (reverse
// Cuthill-McKee by default, node_order.hpp), with the elements sorted by their nodes in the
// new order. The caller keeps the mesh's numbering: the state and the interaction forces are
// mapped in and out at the step's boundary.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <vector>

#include "chapters/08_element_kernels/step.hpp"
#include "chapters/11_node_order/node_order.hpp"

namespace fem::ch11 {

// Order: the nodes renumbered, the elements sorted along them.
class RenumberedNodes {
 public:
  struct Params {
    Ordering ordering = Ordering::rcm;
  };
  static constexpr const char* kName = "nodes renumbered, elements sorted along them";
  static constexpr std::string_view kChapter = FEM_PART_CHAPTER;

  RenumberedNodes(const Scene& scene, const Params& params);
  const Scene& scene() const { return scene_; }  // in the new numbering
  // The caller's constraints, renamed into the new numbering.
  void set_constraints(const std::vector<NodeConstraint>& constraints);
  // Chapter 09 colours groups of 16 consecutive elements, and its pass goes colour by colour:
  // every colour visits the whole mesh, so a node's blocks of A are fetched again for every
  // colour among its elements' groups (the plate: 62 colours). Sorted along the mesh,
  // consecutive elements form a slab: 64 slabs need a handful of colours (the plate: 5), and
  // the pass walks A about once. (The slabs depend on the mesh only, so the state stays the
  // same for any thread count; the test ch11_node_order.cpp counts the colours.)
  int element_group() const;

  // The caller's state in the mesh's numbering, in and out; the step in between.
  template <class Step>
  void step(State& state, Step&& inner) {
    map_in(state);
    inner(inner_);
    map_out(state);
  }
  // The forces name the mesh's nodes: renamed on the way in (a bad one is left to the
  // stepper's check, which refuses it in the caller's numbering), and back for the accessor.
  const std::vector<ExternalForce>& inward(const std::vector<ExternalForce>& forces);
  void outward(const Eigen::SparseVector<double>& f_ext);
  const Eigen::SparseVector<double>& outward_forces(const Eigen::SparseVector<double>&) const {
    return caller_f_ext_;
  }

  const NodeOrder& node_order() const { return order_; }
  Ordering ordering() const { return ordering_; }

 private:
  RenumberedNodes(const Scene& scene, Ordering ordering, NodeOrder order);
  void map_in(const State& caller);
  void map_out(State& caller) const;

  static constexpr int kSlabs = 64;  // element groups of the parallel pass
  Ordering ordering_;
  NodeOrder order_;
  Scene scene_;
  State inner_;  // the state in the new numbering, kept so that a step allocates nothing
  std::vector<ExternalForce> renamed_forces_;
  Eigen::SparseVector<double> caller_f_ext_;
};

}  // namespace fem::ch11
