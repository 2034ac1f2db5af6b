// Draws the scene with OpenGL 3.3 core: the shaded boundary surface of the deforming
// mesh (per-vertex normals), a checkered floor, the constrained nodes as coloured points
// and the mouse spring as a line. Needs a current OpenGL context.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "apps/viewer/camera.hpp"
#include "apps/viewer/session.hpp"

namespace fem::viewer {

class Renderer {
 public:
  Renderer();  // compiles the shaders; throws std::runtime_error with the GL log on failure
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Uploads what does not move: the surface triangles, the floor, the constraint colours.
  void set_scene(const Scene& scene);
  void draw(const State& state, const std::optional<Grab>& grab, const OrbitCamera& camera,
            int width, int height);

 private:
  struct Mesh {  // a vertex array with one interleaved buffer (position, normal or colour)
    unsigned vao = 0, vbo = 0, ebo = 0;
    int count = 0;
  };
  void upload_surface(const Eigen::VectorXd& x);
  void upload_points(const State& state, const std::optional<Grab>& grab);

  unsigned lit_program_ = 0, flat_program_ = 0, floor_program_ = 0;
  Mesh surface_, floor_, points_;  // points_ ends with the spring's two ends
  bool draw_spring_ = false;
  std::vector<Eigen::Vector3i> triangles_;
  std::vector<int> constrained_nodes_;
  std::vector<Eigen::Vector3f> constraint_colours_;
  std::vector<float> scratch_;  // interleaved vertex data, reused every frame
  Eigen::Matrix3Xf normals_;
  float point_size_ = 6.0f;
};

}  // namespace fem::viewer
