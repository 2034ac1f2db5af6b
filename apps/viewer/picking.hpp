// Which surface node is under the mouse: the ray against the boundary triangles at the
// current positions (Moller & Trumbore 1997), then the hit triangle's nearest corner.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "apps/viewer/camera.hpp"

namespace fem::viewer {

struct SurfaceHit {
  int node = -1;          // the hit triangle's corner nearest to the hit point
  double distance = 0.0;  // along the ray
  Eigen::Vector3d point;  // where the ray meets the surface
};

// The nearest hit in front of the ray's origin, if any. x stacks the node positions.
std::optional<SurfaceHit> pick_surface(const Ray& ray, const Eigen::VectorXd& x,
                                       const std::vector<Eigen::Vector3i>& triangles);

// The distance along the ray to the triangle (a, b, c), if the ray meets it in front.
std::optional<double> intersect_triangle(const Ray& ray, const Eigen::Vector3d& a,
                                         const Eigen::Vector3d& b, const Eigen::Vector3d& c);

}  // namespace fem::viewer
