#include "apps/viewer/camera.hpp"

#include <algorithm>
#include <cmath>

namespace fem::viewer {

void OrbitCamera::frame(const Eigen::AlignedBox3d& box) {
  target = box.center();
  const double radius = std::max(0.5 * box.diagonal().norm(), 1e-6);
  distance = 1.3 * radius / std::sin(0.5 * fov_y);
  near_plane = 1e-3 * distance;
  far_plane = 100.0 * distance;
}

void OrbitCamera::orbit(double dx_pixels, double dy_pixels) {
  constexpr double kRadiansPerPixel = 0.006;
  yaw -= kRadiansPerPixel * dx_pixels;
  pitch = std::clamp(pitch + kRadiansPerPixel * dy_pixels, -1.5, 1.5);
}

void OrbitCamera::zoom(double wheel_steps) { distance *= std::pow(0.9, wheel_steps); }

void OrbitCamera::pan(double dx_pixels, double dy_pixels, int viewport_height) {
  // One pixel at the target's depth spans this many metres.
  const double metres = 2.0 * distance * std::tan(0.5 * fov_y) / std::max(viewport_height, 1);
  const Eigen::Vector3d right = forward().cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d up = right.cross(forward());
  target += metres * (-dx_pixels * right + dy_pixels * up);
}

Eigen::Vector3d OrbitCamera::forward() const {
  return -Eigen::Vector3d(std::cos(pitch) * std::cos(yaw), std::cos(pitch) * std::sin(yaw),
                          std::sin(pitch));
}

Eigen::Vector3d OrbitCamera::eye() const { return target - distance * forward(); }

Eigen::Matrix4f OrbitCamera::view() const {
  const Eigen::Vector3d f = forward();
  const Eigen::Vector3d s = f.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d u = s.cross(f);
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.block<1, 3>(0, 0) = s.transpose();
  m.block<1, 3>(1, 0) = u.transpose();
  m.block<1, 3>(2, 0) = -f.transpose();
  m(0, 3) = -s.dot(eye());
  m(1, 3) = -u.dot(eye());
  m(2, 3) = f.dot(eye());
  return m.cast<float>();
}

Eigen::Matrix4f OrbitCamera::projection(double aspect) const {
  const double t = 1.0 / std::tan(0.5 * fov_y);
  Eigen::Matrix4d p = Eigen::Matrix4d::Zero();
  p(0, 0) = t / aspect;
  p(1, 1) = t;
  p(2, 2) = (far_plane + near_plane) / (near_plane - far_plane);
  p(2, 3) = 2.0 * far_plane * near_plane / (near_plane - far_plane);
  p(3, 2) = -1.0;
  return p.cast<float>();
}

Ray OrbitCamera::ray(double px, double py, int width, int height) const {
  const double aspect = static_cast<double>(width) / std::max(height, 1);
  const double ndc_x = 2.0 * px / std::max(width, 1) - 1.0;
  const double ndc_y = 1.0 - 2.0 * py / std::max(height, 1);
  const double t = std::tan(0.5 * fov_y);
  const Eigen::Vector3d f = forward();
  const Eigen::Vector3d s = f.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d u = s.cross(f);
  return {eye(), (f + ndc_x * t * aspect * s + ndc_y * t * u).normalized()};
}

Eigen::Vector2d OrbitCamera::project(const Eigen::Vector3d& p, int width, int height) const {
  const double aspect = static_cast<double>(width) / std::max(height, 1);
  const Eigen::Vector4d clip = projection(aspect).cast<double>() * view().cast<double>() *
                               Eigen::Vector4d(p.x(), p.y(), p.z(), 1.0);
  const Eigen::Vector2d ndc = clip.head<2>() / clip.w();
  return {0.5 * (ndc.x() + 1.0) * width, 0.5 * (1.0 - ndc.y()) * height};
}

Eigen::Vector3d intersect_plane(const Ray& ray, const Eigen::Vector3d& point,
                                const Eigen::Vector3d& normal) {
  const double denominator = ray.direction.dot(normal);
  if (std::abs(denominator) < 1e-12) return ray.origin;
  return ray.origin + ((point - ray.origin).dot(normal) / denominator) * ray.direction;
}

}  // namespace fem::viewer
