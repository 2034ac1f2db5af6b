// Mouse and keys, turned into camera moves and the mouse spring. The input of a frame
// comes from the window or from a scripted drag (--replay-drag), through the same code,
// so that the headless test exercises what a user does.
#pragma once

#include <optional>
#include <string>

#include "apps/viewer/camera.hpp"
#include "apps/viewer/session.hpp"

namespace fem::viewer {

struct MouseInput {
  double x = 0.0, y = 0.0;  // pixels, from the window's top-left corner
  bool left = false, right = false, middle = false;
  double wheel = 0.0;  // steps scrolled this frame, > 0 away from the user
};

// Left button on the body: grab the surface node under the cursor and pull it with the
// spring in the plane facing the camera. Left on the background: orbit. Right or
// middle: pan. Wheel: zoom.
class MouseControls {
 public:
  void update(const MouseInput& mouse, bool over_panel, int width, int height, OrbitCamera& camera,
              Session& session);

 private:
  enum class Mode { None, Orbit, Pan, Drag };
  Mode mode_ = Mode::None;
  MouseInput last_;
  Eigen::Vector3d plane_point_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d plane_normal_ = Eigen::Vector3d::UnitZ();
};

// A scripted drag, in fractions of the window: the left button goes down at `from` at
// frame `press_frame`, moves in a straight line to `to` over `move_frames` frames and
// stays down. "auto" picks a point on the face of the body's far end (max x) that faces
// the camera and pulls it up by a fifth of the window's height.
class DragReplay {
 public:
  // Parses "auto" or "x0,y0,x1,y1"; throws std::invalid_argument with the reason.
  static DragReplay parse(const std::string& spec, int total_frames);

  MouseInput input(int frame, int width, int height, const OrbitCamera& camera,
                   const Session& session);

 private:
  bool automatic_ = true;
  Eigen::Vector2d from_ = Eigen::Vector2d::Zero(), to_ = Eigen::Vector2d::Zero();
  int press_frame_ = 3, move_frames_ = 10;
};

}  // namespace fem::viewer
