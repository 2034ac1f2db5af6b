#include "apps/viewer/controls.hpp"

#include <algorithm>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "apps/viewer/picking.hpp"
#include "common/cli.hpp"

namespace fem::viewer {

void MouseControls::update(const MouseInput& mouse, bool over_panel, int width, int height,
                           OrbitCamera& camera, Session& session) {
  const double dx = mouse.x - last_.x, dy = mouse.y - last_.y;
  const bool left_pressed = mouse.left && !last_.left;
  const bool other_pressed = (mouse.right && !last_.right) || (mouse.middle && !last_.middle);
  const Ray ray = camera.ray(mouse.x, mouse.y, width, height);

  if (mode_ == Mode::None && !over_panel) {
    if (left_pressed) {
      const std::optional<SurfaceHit> hit =
          pick_surface(ray, session.state().x, session.scene().mesh.boundary);
      if (hit) {
        mode_ = Mode::Drag;
        plane_point_ = hit->point;
        plane_normal_ = camera.forward();
        session.grab(hit->node, hit->point);
      } else {
        mode_ = Mode::Orbit;
      }
    } else if (other_pressed) {
      mode_ = Mode::Pan;
    }
    if (mouse.wheel != 0.0) camera.zoom(mouse.wheel);
  }

  switch (mode_) {
    case Mode::Drag:
      if (mouse.left)
        session.move_grab(intersect_plane(ray, plane_point_, plane_normal_));
      else
        session.release();
      break;
    case Mode::Orbit:
      camera.orbit(dx, dy);
      break;
    case Mode::Pan:
      camera.pan(dx, dy, height);
      break;
    case Mode::None:
      break;
  }
  if (!mouse.left && !mouse.right && !mouse.middle) mode_ = Mode::None;
  if (mode_ == Mode::Drag && !session.grabbed()) mode_ = Mode::None;  // e.g. after a reset
  last_ = mouse;
}

DragReplay DragReplay::parse(const std::string& spec, int total_frames) {
  DragReplay replay;
  replay.press_frame_ = std::min(3, std::max(total_frames / 10, 1));
  replay.move_frames_ = std::max((total_frames - replay.press_frame_) / 3, 1);
  if (spec == "auto") return replay;
  std::vector<double> values;
  std::stringstream in(spec);
  std::string item;
  while (std::getline(in, item, ',')) {
    const std::optional<double> value = parse_double(item);
    if (!value) throw std::invalid_argument("--replay-drag: '" + item + "' is not a number");
    values.push_back(*value);
  }
  if (values.size() != 4)
    throw std::invalid_argument(
        "--replay-drag takes 'auto' or x0,y0,x1,y1 (fractions of the window)");
  for (const double v : values)
    if (!(v >= 0.0 && v <= 1.0))
      throw std::invalid_argument(
          "--replay-drag: coordinates are fractions of the window, in [0, 1]");
  replay.automatic_ = false;
  replay.from_ = {values[0], values[1]};
  replay.to_ = {values[2], values[3]};
  return replay;
}

namespace {

// The centre of a boundary triangle at the body's far end (max x) that faces the camera:
// a point that is certainly on the surface, unlike a corner on the silhouette.
Eigen::Vector3d far_end_point(const OrbitCamera& camera, const Session& session) {
  const Eigen::VectorXd& x = session.state().x;
  const auto& triangles = session.scene().mesh.boundary;
  Eigen::Vector3d best = x.head<3>();
  double best_x = -INFINITY;
  for (const Eigen::Vector3i& t : triangles) {
    const Eigen::Vector3d a = x.segment<3>(3 * t[0]), b = x.segment<3>(3 * t[1]),
                          c = x.segment<3>(3 * t[2]);
    const Eigen::Vector3d centre = (a + b + c) / 3.0;
    const bool faces_camera = (b - a).cross(c - a).dot(camera.eye() - centre) > 0.0;
    if (faces_camera && centre.x() > best_x) {
      best_x = centre.x();
      best = centre;
    }
  }
  return best;
}

}  // namespace

MouseInput DragReplay::input(int frame, int width, int height, const OrbitCamera& camera,
                             const Session& session) {
  if (automatic_ && frame == 0) {
    const Eigen::Vector2d pixel = camera.project(far_end_point(camera, session), width, height);
    from_ = {pixel.x() / width, pixel.y() / height};
    to_ = {from_.x(), std::max(from_.y() - 0.2, 0.0)};
  }
  const double s = std::clamp(static_cast<double>(frame - press_frame_) / move_frames_, 0.0, 1.0);
  const Eigen::Vector2d at = from_ + s * (to_ - from_);
  MouseInput mouse;
  mouse.x = at.x() * width;
  mouse.y = at.y() * height;
  mouse.left = frame >= press_frame_;
  return mouse;
}

}  // namespace fem::viewer
