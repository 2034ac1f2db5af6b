// The discretized body: what every chapter precomputes from a scene (rest shapes,
// rest stiffness K0, lumped mass) and the per-step element work they all share
// (rotations and elastic forces). Chapters differ only in what they do afterwards.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "common/element.hpp"
#include "common/scene.hpp"

namespace fem {

struct Model {
  explicit Model(const Scene& scene);

  int num_nodes = 0;
  int dofs = 0;                       // 3 * num_nodes
  std::vector<Eigen::Vector4i> tets;  // node indices per element
  std::vector<ElementRest> rest;      // per element: Dm^-1, volume, K0, X_e
  Eigen::VectorXd lumped_mass;        // per dof: rho * (sum of adjacent volumes) / 4
  Eigen::VectorXd gravity_force;      // per dof: m_i g
};

// Per element: the rotation R_e of the polar decomposition of F_e (written to
// rotations), and the elastic force plus gravity summed into f (3N). The same code in
// every chapter, and allocation-free: vectors are sized by the caller once.
void compute_rotations_and_forces(const Model& model, const Eigen::VectorXd& x,
                                  std::vector<Eigen::Matrix3d>& rotations, Eigen::VectorXd& f);

// Gathers the 12 coordinates of an element from a stacked vector.
inline Vector12d gather(const Eigen::VectorXd& q, const Eigen::Vector4i& tet) {
  Vector12d out;
  for (int a = 0; a < 4; ++a) out.segment<3>(3 * a) = q.segment<3>(3 * tet[a]);
  return out;
}

// Total elastic energy of the body at x (diagnostics and tests).
double elastic_energy(const Model& model, const Scene& scene, const Eigen::VectorXd& x);

}  // namespace fem
