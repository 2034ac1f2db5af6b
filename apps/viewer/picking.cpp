#include "apps/viewer/picking.hpp"

#include <cmath>

namespace fem::viewer {

std::optional<double> intersect_triangle(const Ray& ray, const Eigen::Vector3d& a,
                                         const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d e1 = b - a, e2 = c - a;
  const Eigen::Vector3d p = ray.direction.cross(e2);
  const double det = e1.dot(p);
  if (std::abs(det) < 1e-14 * e1.norm() * e2.norm()) return std::nullopt;  // parallel
  const Eigen::Vector3d s = ray.origin - a;
  const double u = s.dot(p) / det;
  if (u < 0.0 || u > 1.0) return std::nullopt;
  const Eigen::Vector3d q = s.cross(e1);
  const double v = ray.direction.dot(q) / det;
  if (v < 0.0 || u + v > 1.0) return std::nullopt;
  const double t = e2.dot(q) / det;
  if (t <= 0.0) return std::nullopt;
  return t;
}

std::optional<SurfaceHit> pick_surface(const Ray& ray, const Eigen::VectorXd& x,
                                       const std::vector<Eigen::Vector3i>& triangles) {
  std::optional<SurfaceHit> best;
  for (const Eigen::Vector3i& tri : triangles) {
    const Eigen::Vector3d a = x.segment<3>(3 * tri[0]);
    const Eigen::Vector3d b = x.segment<3>(3 * tri[1]);
    const Eigen::Vector3d c = x.segment<3>(3 * tri[2]);
    const std::optional<double> t = intersect_triangle(ray, a, b, c);
    if (!t || (best && *t >= best->distance)) continue;
    SurfaceHit hit;
    hit.distance = *t;
    hit.point = ray.origin + *t * ray.direction;
    double nearest = INFINITY;
    for (int k = 0; k < 3; ++k) {
      const double d = (x.segment<3>(3 * tri[k]) - hit.point).squaredNorm();
      if (d < nearest) {
        nearest = d;
        hit.node = tri[k];
      }
    }
    best = hit;
  }
  return best;
}

}  // namespace fem::viewer
