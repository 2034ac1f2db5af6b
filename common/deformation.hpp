// What a step can do to the body that linear elasticity cannot describe, counted so that a
// program can say so: a tetrahedron turned inside out, or a node thrown further than the
// body is large. The corotated model still returns finite numbers then (its rotation is
// proper also for inverted elements), so a check of finiteness alone would stay silent while
// a time step far too large stretches a 1 m plate to many times its size.
#pragma once

#include <Eigen/Core>

#include "common/mesh.hpp"

namespace fem {

struct DeformationCheck {
  int inverted = 0;           // tetrahedra with det(F) <= 0 (det Ds <= 0: det Dm > 0 on load)
  double largest_move = 0.0;  // max_i |x_i - X_i|
  double body_size = 0.0;     // the diagonal of the rest shape's bounding box

  bool implausible() const { return inverted > 0 || largest_move > body_size; }
};

// The check of one state x (3N, node i at 3i..3i+2) of the mesh: one pass over the elements.
DeformationCheck check_deformation(const TetMesh& mesh, const Eigen::VectorXd& x);

// Counts the implausible steps of a run and warns on the first one (once, as a capped
// solve is reported), then once more at the end with the count.
class DeformationReport {
 public:
  void after_step(int step, const DeformationCheck& check);
  void summary(int steps) const;
  int implausible_steps() const { return implausible_steps_; }

 private:
  int implausible_steps_ = 0;
  int most_inverted_ = 0;
  double largest_move_ = 0.0, body_size_ = 0.0;
};

}  // namespace fem
