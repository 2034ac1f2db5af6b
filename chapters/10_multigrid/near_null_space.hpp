// Chapter 10: the near-null space, the second stage: the motions that cost (almost) no energy,
// which the coarse space must represent exactly. For elasticity the rigid-body modes at the
// rest positions (Vanek, Mandel & Brezina 1996), filtered by the constraints, and improved on
// the first matrix by a few Gauss-Seidel sweeps on A B = 0 (PyAMG's improve_candidates).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "chapters/10_multigrid/level.hpp"
#include "common/scene.hpp"

namespace fem::ch10 {

using NodeModes = Eigen::Matrix<double, 3, kModes>;

// The 3 translations and the 3 rotations w x (X_i - c) about the aggregate's centroid c
// (centring changes nothing in the span but keeps the columns' scales close), filtered by S_i:
// a constrained direction is not free to move, so it is not part of the coarse space either.
// modes = 3: the translations only (the rotations' columns stay zero).
std::vector<NodeModes> rigid_body_modes(const Eigen::VectorXd& X,
                                        const std::vector<NodeConstraint>& constraints,
                                        const std::vector<int>& aggregate, int count, int modes);

// Gauss-Seidel on A x = 0 for each column of the modes, `sweeps` symmetric sweeps on the
// whole matrix in one thread: what is left of each mode is closer to A's near-null space.
void improve_modes(const Level<3>& level, int sweeps, std::vector<NodeModes>& modes);

}  // namespace fem::ch10
