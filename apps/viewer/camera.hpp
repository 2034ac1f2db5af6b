// An orbit camera around a target point, z up, and the mouse rays it casts: what the
// viewer needs to draw the body and to find the surface point under the cursor.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace fem::viewer {

struct Ray {
  Eigen::Vector3d origin;
  Eigen::Vector3d direction;  // unit length
};

class OrbitCamera {
 public:
  // Looks at the box from the front-right, above, at a distance that shows all of it.
  void frame(const Eigen::AlignedBox3d& box);

  void orbit(double dx_pixels, double dy_pixels);  // drag: yaw and pitch
  void zoom(double wheel_steps);                   // > 0 moves closer
  void pan(double dx_pixels, double dy_pixels, int viewport_height);

  Eigen::Vector3d eye() const;
  Eigen::Vector3d forward() const;  // unit vector from the eye to the target
  Eigen::Matrix4f view() const;
  Eigen::Matrix4f projection(double aspect) const;

  // The ray through a pixel (origin at the window's top-left corner, y down).
  Ray ray(double px, double py, int width, int height) const;
  // The pixel a point projects to (same convention); the point must be in front.
  Eigen::Vector2d project(const Eigen::Vector3d& p, int width, int height) const;

  Eigen::Vector3d target = Eigen::Vector3d::Zero();
  double yaw = -0.9;    // [rad] around z, from +x
  double pitch = 0.45;  // [rad] above the xy plane
  double distance = 3.0;
  double fov_y = 0.7;  // [rad]
  double near_plane = 0.01, far_plane = 100.0;
};

// Where a ray meets the plane through `point` with normal `normal` (the drag plane,
// facing the camera). Returns the ray's origin when they are parallel.
Eigen::Vector3d intersect_plane(const Ray& ray, const Eigen::Vector3d& point,
                                const Eigen::Vector3d& normal);

}  // namespace fem::viewer
