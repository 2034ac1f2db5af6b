#include "common/scene.hpp"

#include <cmath>
#include <stdexcept>

namespace fem {

NodeConstraint NodeConstraint::plane(int node, const Eigen::Vector3d& normal) {
  const Eigen::Vector3d p = normal.normalized();
  return {node, Kind::Plane, Eigen::Matrix3d::Identity() - p * p.transpose(),
          Eigen::Vector3d::Zero()};
}

NodeConstraint NodeConstraint::line(int node, const Eigen::Vector3d& direction) {
  const Eigen::Vector3d d = direction.normalized();
  return {node, Kind::Line, d * d.transpose(), Eigen::Vector3d::Zero()};
}

NodeConstraint NodeConstraint::fixed(int node, const Eigen::Vector3d& velocity) {
  return {node, Kind::Fixed, Eigen::Matrix3d::Zero(), velocity};
}

State rest_state(const Scene& scene) {
  State s;
  s.x = Eigen::Map<const Eigen::VectorXd>(scene.mesh.X.data(), scene.mesh.X.size());
  s.v = Eigen::VectorXd::Zero(s.x.size());
  return s;
}

const std::vector<std::string>& scene_names() {
  static const std::vector<std::string> names = {"cantilever", "sliding"};
  return names;
}

Scene make_scene(const std::string& name, TetMesh mesh, const Material& material) {
  Scene scene;
  scene.name = name;
  scene.material = material;
  const Eigen::Vector3d lo = mesh.X.rowwise().minCoeff();
  const Eigen::Vector3d hi = mesh.X.rowwise().maxCoeff();
  const double tol = 1e-6 * (hi - lo).maxCoeff();
  const auto near = [tol](double a, double b) { return std::abs(a - b) <= tol; };

  if (name == "cantilever") {
    for (int i = 0; i < mesh.num_nodes(); ++i)
      if (near(mesh.X(0, i), lo.x())) scene.constraints.push_back(NodeConstraint::fixed(i));
  } else if (name == "sliding") {
    int pushed = 0;
    for (int i = 0; i < mesh.num_nodes(); ++i) {
      const Eigen::Vector3d p = mesh.X.col(i);
      const bool bottom = near(p.z(), lo.z());
      if (bottom && near(p.x(), lo.x()) && near(p.y(), lo.y()))
        scene.constraints.push_back(NodeConstraint::fixed(i));
      else if (bottom && near(p.y(), lo.y()))
        scene.constraints.push_back(NodeConstraint::line(i, Eigen::Vector3d::UnitX()));
      else if (bottom)
        scene.constraints.push_back(NodeConstraint::plane(i, Eigen::Vector3d::UnitZ()));
      else if (near(p.z(), hi.z()) && near(p.x(), hi.x()))
        ++pushed;
    }
    // Spread a total of 'push' newtons over the top nodes at max x, so the scene does
    // the same thing whatever the resolution: a sparse force, as a mouse drag would be.
    const double mass = material.density * (hi - lo).prod();
    const double push = 2.0 * mass;  // [N], an acceleration of about 2 m/s^2
    for (int i = 0; i < mesh.num_nodes() && pushed > 0; ++i) {
      const Eigen::Vector3d p = mesh.X.col(i);
      if (!near(p.z(), lo.z()) && near(p.z(), hi.z()) && near(p.x(), hi.x()))
        scene.external_forces.push_back({i, Eigen::Vector3d(0.0, push / pushed, 0.0)});
    }
  } else {
    throw std::invalid_argument("unknown scene '" + name + "' (known: cantilever, sliding)");
  }
  scene.mesh = std::move(mesh);
  validate(scene);
  return scene;
}

void validate(const Scene& scene) {
  const auto bad = [](const std::string& what) { throw std::invalid_argument(what); };
  const Material& m = scene.material;
  if (!(m.youngs_modulus > 0.0) || !std::isfinite(m.youngs_modulus))
    bad("Young's modulus E must be positive and finite");
  if (!(m.poisson_ratio > -1.0 && m.poisson_ratio < 0.5))
    bad("Poisson's ratio nu must lie in (-1, 0.5)");
  if (!(m.density > 0.0) || !std::isfinite(m.density)) bad("density rho must be positive");
  if (!(scene.dt > 0.0) || !std::isfinite(scene.dt)) bad("time step dt must be positive");
  if (!(scene.damping.alpha >= 0.0) || !(scene.damping.beta >= 0.0))
    bad("Rayleigh damping alpha and beta must be non-negative");
  if (!scene.gravity.allFinite()) bad("gravity must be finite");
  std::vector<bool> constrained(static_cast<std::size_t>(scene.mesh.num_nodes()), false);
  for (const auto& c : scene.constraints) {
    if (c.node < 0 || c.node >= scene.mesh.num_nodes()) bad("a constraint names a missing node");
    if (constrained[c.node]) bad("node " + std::to_string(c.node) + " has two constraints");
    constrained[c.node] = true;
  }
  for (const auto& f : scene.external_forces)
    if (f.node < 0 || f.node >= scene.mesh.num_nodes() || !f.force.allFinite())
      bad("an external force names a missing node or is not finite");
}

}  // namespace fem
