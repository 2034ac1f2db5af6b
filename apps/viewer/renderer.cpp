#include "apps/viewer/renderer.hpp"

// The core-profile prototypes, resolved by libGL (glvnd) at link time: no loader needed.
#define GL_GLEXT_PROTOTYPES
#include <GL/glcorearb.h>

#include <stdexcept>

#include "apps/viewer/markers.hpp"

namespace fem::viewer {

namespace {

const char* const kLitVertex = R"(#version 330 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
uniform mat4 view_projection;
out vec3 world_normal;
out vec3 world_position;
void main() {
  world_normal = normal;
  world_position = position;
  gl_Position = view_projection * vec4(position, 1.0);
})";

// A headlight (the light sits at the eye), lit on both sides: the surface of a mesh
// that is being pulled around can show its inside for a moment.
const char* const kLitFragment = R"(#version 330 core
in vec3 world_normal;
in vec3 world_position;
uniform vec3 eye;
uniform vec3 colour;
out vec4 fragment;
void main() {
  vec3 n = normalize(world_normal);
  vec3 to_eye = normalize(eye - world_position);
  float diffuse = abs(dot(n, to_eye));
  float specular = pow(max(dot(reflect(-to_eye, n), to_eye), 0.0), 32.0);
  fragment = vec4(colour * (0.25 + 0.75 * diffuse) + vec3(0.15 * specular), 1.0);
})";

const char* const kFlatVertex = R"(#version 330 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 colour;
uniform mat4 view_projection;
uniform float point_size;
out vec3 vertex_colour;
void main() {
  vertex_colour = colour;
  gl_PointSize = point_size;
  gl_Position = view_projection * vec4(position, 1.0);
})";

const char* const kFlatFragment = R"(#version 330 core
in vec3 vertex_colour;
out vec4 fragment;
void main() { fragment = vec4(vertex_colour, 1.0); })";

const char* const kFloorVertex = R"(#version 330 core
layout(location = 0) in vec3 position;
uniform mat4 view_projection;
out vec2 floor_xy;
void main() {
  floor_xy = position.xy;
  gl_Position = view_projection * vec4(position, 1.0);
})";

const char* const kFloorFragment = R"(#version 330 core
in vec2 floor_xy;
uniform float tile;
out vec4 fragment;
void main() {
  vec2 cell = floor(floor_xy / tile);
  float checker = mod(cell.x + cell.y, 2.0);
  fragment = vec4(mix(vec3(0.55), vec3(0.68), checker), 1.0);
})";

unsigned compile(GLenum type, const char* source) {
  const GLuint shader = glCreateShader(type);
  glShaderSource(shader, 1, &source, nullptr);
  glCompileShader(shader);
  GLint ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[2048];
    glGetShaderInfoLog(shader, sizeof log, nullptr, log);
    throw std::runtime_error(std::string("shader compilation failed: ") + log);
  }
  return shader;
}

unsigned link(const char* vertex, const char* fragment) {
  const GLuint vs = compile(GL_VERTEX_SHADER, vertex);
  const GLuint fs = compile(GL_FRAGMENT_SHADER, fragment);
  const GLuint program = glCreateProgram();
  glAttachShader(program, vs);
  glAttachShader(program, fs);
  glLinkProgram(program);
  glDeleteShader(vs);
  glDeleteShader(fs);
  GLint ok = 0;
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[2048];
    glGetProgramInfoLog(program, sizeof log, nullptr, log);
    throw std::runtime_error(std::string("shader link failed: ") + log);
  }
  return program;
}

// Two vec3 attributes, interleaved: position at location 0, normal or colour at 1.
void make_vertex_array(unsigned& vao, unsigned& vbo) {
  glGenVertexArrays(1, &vao);
  glGenBuffers(1, &vbo);
  glBindVertexArray(vao);
  glBindBuffer(GL_ARRAY_BUFFER, vbo);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), nullptr);
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float),
                        reinterpret_cast<const void*>(3 * sizeof(float)));
}

void upload(unsigned vbo, const std::vector<float>& data) {
  glBindBuffer(GL_ARRAY_BUFFER, vbo);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(data.size() * sizeof(float)), data.data(),
               GL_STREAM_DRAW);
}

void push(std::vector<float>& out, const Eigen::Vector3f& a, const Eigen::Vector3f& b) {
  out.insert(out.end(), {a.x(), a.y(), a.z(), b.x(), b.y(), b.z()});
}

void set_matrix(unsigned program, const char* name, const Eigen::Matrix4f& m) {
  glUniformMatrix4fv(glGetUniformLocation(program, name), 1, GL_FALSE, m.data());
}

Eigen::Vector3f colour(const Marker& marker) {
  return {marker.rgb[0], marker.rgb[1], marker.rgb[2]};
}

}  // namespace

Renderer::Renderer() {
  lit_program_ = link(kLitVertex, kLitFragment);
  flat_program_ = link(kFlatVertex, kFlatFragment);
  floor_program_ = link(kFloorVertex, kFloorFragment);
  for (Mesh* m : {&surface_, &floor_, &points_}) make_vertex_array(m->vao, m->vbo);
  glBindVertexArray(surface_.vao);
  glGenBuffers(1, &surface_.ebo);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, surface_.ebo);
  glBindVertexArray(0);
}

Renderer::~Renderer() {
  for (Mesh* m : {&surface_, &floor_, &points_}) {
    glDeleteBuffers(1, &m->vbo);
    if (m->ebo) glDeleteBuffers(1, &m->ebo);
    glDeleteVertexArrays(1, &m->vao);
  }
  for (const unsigned p : {lit_program_, flat_program_, floor_program_}) glDeleteProgram(p);
}

void Renderer::set_scene(const Scene& scene) {
  triangles_ = scene.mesh.boundary;
  glBindVertexArray(surface_.vao);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, surface_.ebo);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER,
               static_cast<GLsizeiptr>(triangles_.size() * sizeof(Eigen::Vector3i)),
               triangles_.data(), GL_STATIC_DRAW);
  surface_.count = static_cast<int>(3 * triangles_.size());
  glBindVertexArray(0);

  constrained_nodes_.clear();
  constraint_colours_.clear();
  for (const NodeConstraint& c : scene.constraints) {
    constrained_nodes_.push_back(c.node);
    constraint_colours_.push_back(colour(constraint_marker(c.kind)));
  }

  // The floor: the plane the sliding scene rests on; under the cantilever, a body length
  // below it, so that it gives depth without being in the way.
  const Eigen::Vector3d lo = scene.mesh.X.rowwise().minCoeff();
  const Eigen::Vector3d hi = scene.mesh.X.rowwise().maxCoeff();
  const double size = (hi - lo).norm();
  const double z = scene.name == "sliding" ? lo.z() : lo.z() - 0.75 * size;
  const Eigen::Vector3d c = 0.5 * (lo + hi);
  const float r = static_cast<float>(1.5 * size);
  std::vector<float> quad;
  const Eigen::Vector3f up = Eigen::Vector3f::UnitZ();
  for (const auto& [sx, sy] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}})
    push(quad, Eigen::Vector3f(c.x() + sx * r, c.y() + sy * r, z), up);
  upload(floor_.vbo, quad);
  floor_.count = 4;
  point_size_ = 6.0f;
}

void Renderer::upload_surface(const Eigen::VectorXd& x) {
  // Per-vertex normals: the area-weighted sum of the adjacent faces' normals (the cross
  // product's length is twice the area, so no weights are computed).
  const Eigen::Index n = x.size() / 3;
  normals_.setZero(3, n);
  for (const Eigen::Vector3i& t : triangles_) {
    const Eigen::Vector3d a = x.segment<3>(3 * t[0]);
    const Eigen::Vector3d face = (x.segment<3>(3 * t[1]) - a).cross(x.segment<3>(3 * t[2]) - a);
    for (int k = 0; k < 3; ++k) normals_.col(t[k]) += face.cast<float>();
  }
  scratch_.resize(6 * n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Vector3f p = x.segment<3>(3 * i).cast<float>();
    const Eigen::Vector3f normal = normals_.col(i).stableNormalized();
    std::copy(p.data(), p.data() + 3, &scratch_[6 * i]);
    std::copy(normal.data(), normal.data() + 3, &scratch_[6 * i + 3]);
  }
  upload(surface_.vbo, scratch_);
}

void Renderer::upload_points(const State& state, const std::optional<Grab>& grab) {
  scratch_.clear();
  for (std::size_t k = 0; k < constrained_nodes_.size(); ++k)
    push(scratch_, state.x.segment<3>(3 * constrained_nodes_[k]).cast<float>(),
         constraint_colours_[k]);
  points_.count = static_cast<int>(constrained_nodes_.size());
  if (grab) {
    const Eigen::Vector3f spring = colour(kSpringMarker);
    const Eigen::Vector3f node = state.x.segment<3>(3 * grab->node).cast<float>();
    push(scratch_, node, spring);
    push(scratch_, grab->target.cast<float>(), spring);
    points_.count += 2;
  }
  upload(points_.vbo, scratch_);
  draw_spring_ = grab.has_value();
}

void Renderer::draw(const State& state, const std::optional<Grab>& grab, const OrbitCamera& camera,
                    int width, int height) {
  glViewport(0, 0, width, height);
  glClearColor(0.16f, 0.18f, 0.22f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  glEnable(GL_DEPTH_TEST);
  glEnable(GL_PROGRAM_POINT_SIZE);
  const Eigen::Matrix4f view_projection =
      camera.projection(static_cast<double>(width) / std::max(height, 1)) * camera.view();

  glUseProgram(floor_program_);
  set_matrix(floor_program_, "view_projection", view_projection);
  glUniform1f(glGetUniformLocation(floor_program_, "tile"),
              static_cast<float>(0.1 * camera.distance));
  glBindVertexArray(floor_.vao);
  glDrawArrays(GL_TRIANGLE_FAN, 0, floor_.count);

  upload_surface(state.x);
  glUseProgram(lit_program_);
  set_matrix(lit_program_, "view_projection", view_projection);
  const Eigen::Vector3f eye = camera.eye().cast<float>();
  glUniform3fv(glGetUniformLocation(lit_program_, "eye"), 1, eye.data());
  glUniform3f(glGetUniformLocation(lit_program_, "colour"), 0.35f, 0.65f, 0.55f);
  glBindVertexArray(surface_.vao);
  glDrawElements(GL_TRIANGLES, surface_.count, GL_UNSIGNED_INT, nullptr);

  // Points and the spring are drawn over the surface, so that hidden constraints show.
  upload_points(state, grab);
  glDisable(GL_DEPTH_TEST);
  glUseProgram(flat_program_);
  set_matrix(flat_program_, "view_projection", view_projection);
  glUniform1f(glGetUniformLocation(flat_program_, "point_size"), point_size_);
  glBindVertexArray(points_.vao);
  glDrawArrays(GL_POINTS, 0, points_.count);
  if (draw_spring_) {
    const GLint first = points_.count - 2;
    glDrawArrays(GL_LINES, first, 2);
  }
  glBindVertexArray(0);
}

}  // namespace fem::viewer
