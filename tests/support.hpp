// Shared helpers for the tests: the committed meshes, small hand-made meshes, and
// running a stepper for a number of steps.
#pragma once

#include <algorithm>
#include <catch2/catch.hpp>
#include <string>
#include <utility>

#include "chapters/registry.hpp"
#include "common/build_info.hpp"
#include "common/mesh.hpp"
#include "common/scene.hpp"

namespace fem::test {

inline std::string mesh_path(const std::string& file) { return source_dir() + "/meshes/" + file; }

// The small committed test mesh: a 1 x 0.1 x 0.1 beam, at most 300 nodes.
inline TetMesh test_mesh() { return load_mesh(mesh_path("test_beam.msh")); }

// A scene on the test mesh (or another) with a material soft enough to move visibly in 50 steps.
inline Scene test_scene(const std::string& name, TetMesh mesh = test_mesh()) {
  Material m;
  m.youngs_modulus = 2e5;
  m.poisson_ratio = 0.3;
  m.density = 1000.0;
  Scene s = make_scene(name, std::move(mesh), m);
  s.dt = 0.01;
  return s;
}

// Runs `steps` steps of a chapter from rest; returns the final state.
inline State run(const std::string& chapter, const Scene& scene, int steps,
                 const SolverSettings& settings = {}) {
  auto stepper = make_stepper(chapter, scene, settings);
  State state = rest_state(scene);
  for (int k = 0; k < steps; ++k) stepper->step(state);
  return state;
}

}  // namespace fem::test

namespace fem::test {

// How far a chapter drifts from chapter 01 when both run the same scene side by side.
struct Drift {
  double x = 0.0, v = 0.0;           // max |x - x01|, max |v - v01| over all steps
  double motion = 0.0, speed = 0.0;  // max |x01 - X|, max |v01|: the scale of the motion
  double relative() const { return std::max(x / motion, v / speed); }
};

// The CG tolerance of the chapter comparisons: tight enough that the solver's error
// (relative residual 1e-12 amplified by the condition number, about 1e3 on the test mesh)
// stays far below the tolerance of the comparison.
inline SolverSettings tight_solver() {
  SolverSettings s;
  s.tolerance = 1e-12;
  s.max_iterations = 10000;
  return s;
}

inline Drift drift_from_ch01(const std::string& chapter, const Scene& scene, int steps) {
  auto reference = make_stepper("01", scene, tight_solver());
  auto candidate = make_stepper(chapter, scene, tight_solver());
  State a = rest_state(scene), b = rest_state(scene);
  const Eigen::VectorXd X = a.x;
  Drift d;
  for (int k = 0; k < steps; ++k) {
    reference->step(a);
    candidate->step(b);
    d.x = std::max(d.x, (a.x - b.x).cwiseAbs().maxCoeff());
    d.v = std::max(d.v, (a.v - b.v).cwiseAbs().maxCoeff());
    d.motion = std::max(d.motion, (a.x - X).cwiseAbs().maxCoeff());
    d.speed = std::max(d.speed, a.v.cwiseAbs().maxCoeff());
  }
  return d;
}

}  // namespace fem::test

#include "common/alloc_counter.hpp"

namespace fem::test {

// Heap allocations of one step after the first, checked to be the same for 5 steps
// (-1 if they differ: a count that is not deterministic is a failure of its own).
inline long long allocations_per_step(const std::string& chapter, const Scene& scene) {
  auto stepper = make_stepper(chapter, scene, {});
  State state = rest_state(scene);
  stepper->step(state);
  long long first = -2;
  for (int k = 0; k < 5; ++k) {
    alloc::Scope scope;
    stepper->step(state);
    const long long n = scope.allocations();
    if (first == -2) first = n;
    if (n != first) return -1;
  }
  return first;
}

}  // namespace fem::test

namespace fem::test {

// The check every chapter passes: the same scene, side by side with chapter 01 for 50
// steps, positions and velocities within 1e-8 of the motion's scale. Why 1e-8: both solve
// to a relative residual of 1e-12, and the test mesh's systems have condition numbers of
// about 1e3, so the solutions may differ by about 1e-9 relative to dv; rounding alone (the
// chapters sum in different orders) is about 1e-14.
inline void check_matches_ch01(const std::string& chapter, const Scene& scene) {
  const Drift d = drift_from_ch01(chapter, scene, 50);
  INFO(chapter << " on " << scene.name << ": max |dx| " << d.x << " of motion " << d.motion
               << ", max |dv| " << d.v << " of speed " << d.speed);
  REQUIRE(d.motion > 1e-3);  // the scene really moves
  CHECK(d.relative() < 1e-8);
}

}  // namespace fem::test

// Allocation tests skip (and say so) where the counter is off: the sanitizer builds.
#define FEM_REQUIRE_ALLOCATION_COUNTER()                       \
  if (!fem::alloc::enabled()) {                                \
    SUCCEED("allocation counting is off in sanitizer builds"); \
    return;                                                    \
  }
