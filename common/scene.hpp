// A scene: the mesh, its material, the time step, gravity, the velocity constraints
// (the poster's per-node filters S_i) and the sparse external "interaction" forces.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "common/mesh.hpp"

namespace fem {

struct Material {
  double youngs_modulus = 1e5;  // E [Pa]: a soft solid, as interactive demos use
  double poisson_ratio = 0.3;   // nu, in (-1, 0.5)
  double density = 1000.0;      // rho [kg/m^3]
};

// Rayleigh damping df/dv = -(alpha M + beta K), with K = -df/dx.
struct RayleighDamping {
  double alpha = 0.1;   // [1/s]
  double beta = 0.005;  // [s]
};

// A velocity constraint on one node: the filter S_i keeps the free directions, and
// the constrained directions follow target_velocity (zero unless a scene drives it).
struct NodeConstraint {
  enum class Kind { Plane, Line, Fixed };
  int node = 0;
  Kind kind = Kind::Fixed;
  Eigen::Matrix3d filter = Eigen::Matrix3d::Zero();  // S_i
  Eigen::Vector3d target_velocity = Eigen::Vector3d::Zero();

  // S_i = I - p p^T: the node moves in the plane with normal p.
  static NodeConstraint plane(int node, const Eigen::Vector3d& normal);
  // S_i = d d^T = I - p p^T - q q^T: the node moves along the line with direction d.
  static NodeConstraint line(int node, const Eigen::Vector3d& direction);
  // S_i = 0: the node moves with target_velocity.
  static NodeConstraint fixed(int node, const Eigen::Vector3d& velocity = Eigen::Vector3d::Zero());
};

struct ExternalForce {
  int node = 0;
  Eigen::Vector3d force = Eigen::Vector3d::Zero();  // [N]
};

struct Scene {
  std::string name;
  TetMesh mesh;
  Material material;
  RayleighDamping damping;
  double dt = 0.01;  // [s]
  Eigen::Vector3d gravity{0.0, 0.0, -9.81};
  std::vector<NodeConstraint> constraints;  // at most one per node
  std::vector<ExternalForce> external_forces;
};

// Nodal positions and velocities, stacked: node i is entries 3i..3i+2.
struct State {
  Eigen::VectorXd x;
  Eigen::VectorXd v;
};

State rest_state(const Scene& scene);

// The built-in scenes, on any mesh. The mesh's axis-aligned bounding box decides
// which nodes are clamped, on the floor, or pushed.
//  cantilever: nodes on the min-x face fixed; the body swings down under gravity.
//  sliding:    resting on a frictionless floor at min z: bottom nodes on the plane
//              z = zmin, the bottom edge at min y on a line along x, one corner fixed;
//              a sideways force (+y) pulls on a few top nodes at max x.
Scene make_scene(const std::string& name, TetMesh mesh, const Material& material = {});
const std::vector<std::string>& scene_names();

// Checks the numbers a user can type (E > 0, -1 < nu < 0.5, rho > 0, dt > 0, finite
// gravity, constraint nodes in range); throws std::invalid_argument naming the problem.
void validate(const Scene& scene);

}  // namespace fem
