// The body's read-outs of force (the floor's release test and friction, reactions(),
// elastic_forces()) node by node: a node's force is the sum over its elements, and each element
// is computed once per set of positions and kept. The floor's contacts and a support's few
// constrained nodes so cost their own elements, not a pass over the body, and an element costs
// what it costs in chapter 12's lanes (chapter 08's Newton rotation warm-started from its last
// one, eight elements at once; the stress in the shape gradients), not common/'s SVD and
// stored K0 one element at a time.
//
// Newton's answer depends on its start in its last bits, and the floor's decisions (release,
// friction) on the forces' bits: so the floor's elements start from the floor's own last
// rotations, and what an app reads never changes a later step.
#pragma once

#include <Eigen/Core>
#include <array>
#include <vector>

#include "chapters/12_half_the_bytes/batch_rotations.hpp"
#include "common/model.hpp"

namespace femcourse::detail {

class NodeForces {
 public:
  // Who asks: the body's floor, which decides by the forces, or an app's read-out.
  enum class Reader : char { app, floor };

  // Allocates here only: every call below reuses this storage.
  NodeForces(const fem::Model& model, const fem::Scene& scene);

  // The positions changed: every node's force is stale.
  void new_positions() { ++version_; }
  // Every element's start back to the rest shape's rotation (a saved or restored state: from
  // then on the state alone decides the floor's forces, to the bit).
  void restart();
  // Computes, in batches, the elements of the nodes node_of(item) for each item of `items` that
  // `reader` cannot take as they are: call it before at() on many nodes.
  template <class Items, class NodeOf>
  void prepare(const Items& items, NodeOf node_of, const Eigen::VectorXd& x, Reader reader) {
    for (const auto& item : items) stage_node(node_of(item), reader);
    compute_staged(x, reader);
  }
  // Elastic force plus gravity at `node` [N] at positions x (those of the last new_positions()).
  Eigen::Vector3d at(int node, const Eigen::VectorXd& x, Reader reader = Reader::app);
  // The same at every node for an app, 3N values: each element not yet computed, once.
  const Eigen::VectorXd& all(const Eigen::VectorXd& x);

 private:
  struct Stamp {
    long long version = -1;     // computed at these positions
    Reader from = Reader::app;  // and from the floor's starts, or an app's
    bool serves(long long version_now, Reader reader) const {
      return version == version_now && (from == Reader::floor || reader == Reader::app);
    }
  };
  using Lanes = fem::ch12::Lanes;
  static constexpr int kLanes = fem::ch12::kLanes;
  void stage_node(int node, Reader reader);
  void compute_staged(const Eigen::VectorXd& x, Reader reader);
  void sum_node(std::size_t n, Reader reader);
  void compute_batch(const int* elements, int count, const Eigen::VectorXd& x, Reader reader);

  const fem::Model& model_;
  // Per element, in arrays over the elements (a batch gathers them lane by lane): Dm^-1 by
  // entries, V mu, V lambda, and Newton's starts (w, x, y, z): the last rotation the floor
  // computed, and the last any reader did (an app's read-out starts there; the floor never does).
  std::array<std::vector<double>, 9> dm_;
  std::vector<double> mu_volume_, lambda_volume_;
  std::array<std::vector<double>, 4> floor_starts_, starts_;
  std::vector<Eigen::Matrix<double, 3, 4>> forces_;  // each element's, on its four corners
  std::vector<Stamp> element_stamps_, node_stamps_;
  // Node n's elements, as 4 e + the node's corner in e, in corners_[first_[n] .. first_[n+1]).
  std::vector<int> first_, corners_;
  std::vector<int> staged_;  // elements to compute, each once
  Eigen::VectorXd f_;
  long long version_ = 0;
  long long fallbacks_ = 0;  // rotations Newton left to the SVD (chapter 12's polar_rotations)
};

}  // namespace femcourse::detail
