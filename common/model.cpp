#include "common/model.hpp"

namespace fem {

Model::Model(const Scene& scene)
    : num_nodes(scene.mesh.num_nodes()), dofs(3 * scene.mesh.num_nodes()), tets(scene.mesh.tets) {
  validate(scene);
  const Lame lame =
      lame_from_young_poisson(scene.material.youngs_modulus, scene.material.poisson_ratio);
  rest.reserve(tets.size());
  lumped_mass = Eigen::VectorXd::Zero(dofs);
  for (const auto& t : tets) {
    Vector12d X;
    for (int a = 0; a < 4; ++a) X.segment<3>(3 * a) = scene.mesh.X.col(t[a]);
    rest.push_back(make_element_rest(X, lame));
    const double node_mass = scene.material.density * rest.back().volume / 4.0;
    for (int a = 0; a < 4; ++a) lumped_mass.segment<3>(3 * t[a]).array() += node_mass;
  }
  gravity_force = lumped_mass.cwiseProduct(scene.gravity.replicate(num_nodes, 1));
}

void compute_rotations_and_forces(const Model& model, const Eigen::VectorXd& x,
                                  std::vector<Eigen::Matrix3d>& rotations, Eigen::VectorXd& f) {
  f = model.gravity_force;  // same size every step: a copy, no allocation
  for (std::size_t e = 0; e < model.tets.size(); ++e) {
    const Eigen::Vector4i& t = model.tets[e];
    const Vector12d xe = gather(x, t);
    const Eigen::Matrix3d& R = rotations[e] =
        polar_rotation(deformation_gradient(model.rest[e], xe));
    const Vector12d fe = element_force(model.rest[e], R, xe);
    for (int a = 0; a < 4; ++a) f.segment<3>(3 * t[a]) += fe.segment<3>(3 * a);
  }
}

double elastic_energy(const Model& model, const Scene& scene, const Eigen::VectorXd& x) {
  const Lame lame =
      lame_from_young_poisson(scene.material.youngs_modulus, scene.material.poisson_ratio);
  double energy = 0.0;
  for (std::size_t e = 0; e < model.tets.size(); ++e)
    energy += element_energy(model.rest[e], lame, gather(x, model.tets[e]));
  return energy;
}

}  // namespace fem
