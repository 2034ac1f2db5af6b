// Shared helpers for the tests: the committed meshes, small hand-made meshes, and
// running a stepper for a number of steps.
#pragma once

#include <algorithm>
#include <string>
#include <utility>
#include <vector>

#include "catch2_compat.hpp"
#include "chapters/registry.hpp"
#include "common/build_info.hpp"
#include "common/mesh.hpp"
#include "common/scene.hpp"

namespace fem::test {

// A soak's steps: under the sanitizers (FEM_SANITIZE), whose instrumentation makes a step
// ten times slower or more, a fifth of them: the same checks, within CI's time. The soaks'
// assertions scale with the steps (refreshes per step) or read a fixed start (energy).
inline int soak_steps(int steps) {
#ifdef FEM_SANITIZED
  return steps / 5;
#else
  return steps;
#endif
}

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

// Chapter 01's states after each of `steps` steps: the reference a test compares several
// chapters with is computed once (chapter 01 is the slowest to step).
inline std::vector<State> ch01_trajectory(const Scene& scene, int steps,
                                          const SolverSettings& settings = tight_solver()) {
  auto reference = make_stepper("01", scene, settings);
  State a = rest_state(scene);
  std::vector<State> states;
  for (int k = 0; k < steps; ++k) {
    reference->step(a);
    states.push_back(a);
  }
  return states;
}

inline Drift drift_from(const std::vector<State>& reference, const std::string& chapter,
                        const Scene& scene, const SolverSettings& settings = tight_solver()) {
  auto candidate = make_stepper(chapter, scene, settings);
  State b = rest_state(scene);
  const Eigen::VectorXd X = b.x;
  Drift d;
  for (const State& a : reference) {
    candidate->step(b);
    d.x = std::max(d.x, (a.x - b.x).cwiseAbs().maxCoeff());
    d.v = std::max(d.v, (a.v - b.v).cwiseAbs().maxCoeff());
    d.motion = std::max(d.motion, (a.x - X).cwiseAbs().maxCoeff());
    d.speed = std::max(d.speed, a.v.cwiseAbs().maxCoeff());
  }
  return d;
}

inline Drift drift_from_ch01(const std::string& chapter, const Scene& scene, int steps,
                             const SolverSettings& settings = tight_solver()) {
  return drift_from(ch01_trajectory(scene, steps, settings), chapter, scene, settings);
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
inline void check_matches_ch01(const std::string& chapter, const Scene& scene,
                               const std::vector<State>& ch01_states) {
  const Drift d = drift_from(ch01_states, chapter, scene);
  INFO(chapter << " on " << scene.name << ": max |dx| " << d.x << " of motion " << d.motion
               << ", max |dv| " << d.v << " of speed " << d.speed);
  REQUIRE(d.motion > 1e-3);  // the scene really moves
  CHECK(d.relative() < 1e-8);
}

inline void check_matches_ch01(const std::string& chapter, const Scene& scene) {
  check_matches_ch01(chapter, scene, ch01_trajectory(scene, 50));
}

// The sliding scene made to exercise every path of the constraints: its planes and lines
// are tilted off the axes (so no filter is a coordinate projection), and every constrained
// node has a target velocity with a component in its constrained directions, so that the
// prescribed velocity change z is non-zero at every step and the chapters' A z path (and
// chapter 07's transposed-block lookup) runs. Every filter case: plane, line, fixed.
inline Scene driven_scene() {
  Scene scene = test_scene("sliding");
  scene.name = "driven";
  const Eigen::Vector3d normal = Eigen::Vector3d(0.2, -0.1, 1.0).normalized();
  const Eigen::Vector3d direction = Eigen::Vector3d(1.0, 0.3, 0.15).normalized();
  for (auto& c : scene.constraints) {
    const int node = c.node;
    switch (c.kind) {
      case NodeConstraint::Kind::Plane:
        c = NodeConstraint::plane(node, normal);
        c.target_velocity = 0.02 * normal;  // the plane itself moves along its normal
        break;
      case NodeConstraint::Kind::Line:
        c = NodeConstraint::line(node, direction);
        c.target_velocity = Eigen::Vector3d(0.0, 0.03, 0.01);  // off the line: drives it
        break;
      case NodeConstraint::Kind::Fixed:
        c = NodeConstraint::fixed(node, Eigen::Vector3d(0.0, 0.05, 0.02));
        break;
    }
  }
  return scene;
}

// The scenes every chapter is compared with chapter 01 on.
inline std::vector<Scene> equivalence_scenes() {
  return {test_scene("cantilever"), test_scene("sliding"), driven_scene()};
}

// Chapter 01 equivalence on the driven scene (it checks first that the scene really has every
// filter case and a non-zero z). The cantilever and the sliding scene are the generic test's
// ("NN: matches chapter 01 on both scenes over 50 steps", tests/generic, label chNN too):
// stepping them here again would double the suite's most expensive check.
inline void check_matches_ch01_on_driven_scene(const std::string& chapter) {
  const Scene driven = driven_scene();
  int kinds[3] = {0, 0, 0};
  for (const auto& c : driven.constraints) {
    ++kinds[static_cast<int>(c.kind)];
    REQUIRE(((Eigen::Matrix3d::Identity() - c.filter) * c.target_velocity).norm() > 0.0);
  }
  REQUIRE(kinds[0] > 0);  // plane
  REQUIRE(kinds[1] > 0);  // line
  REQUIRE(kinds[2] > 0);  // fixed
  check_matches_ch01(chapter, driven);
}

// Rayleigh mass damping alone on a rigid translation (no gravity, no constraints, no
// stiffness damping): the elastic force and df/dx v vanish, so A dv = b reduces to
// (1 + h alpha) M dv = -h alpha M v, and the speed decays by exactly 1 / (1 + h alpha)
// per step. Any chapter that drops or doubles a damping term fails it.
inline void check_damping_rate(const std::string& chapter) {
  Scene scene = test_scene("cantilever");
  scene.constraints.clear();
  scene.external_forces.clear();
  scene.gravity.setZero();
  scene.damping = {2.0, 0.0};
  auto stepper = make_stepper(chapter, scene, tight_solver());
  State state = rest_state(scene);
  const Eigen::Vector3d v0(0.3, -0.2, 0.1);
  for (int i = 0; i < scene.mesh.num_nodes(); ++i) state.v.segment<3>(3 * i) = v0;
  const double rate = 1.0 / (1.0 + scene.dt * scene.damping.alpha);
  double expected = 1.0;
  for (int k = 0; k < 20; ++k) {
    stepper->step(state);
    expected *= rate;
    Eigen::VectorXd v_expected(state.v.size());
    for (int i = 0; i < scene.mesh.num_nodes(); ++i) v_expected.segment<3>(3 * i) = expected * v0;
    INFO(chapter << " step " << k + 1 << ": expected speed factor " << expected);
    CHECK((state.v - v_expected).cwiseAbs().maxCoeff() <= 1e-10 * v0.norm());
  }
}

// At the tolerance the benchmark and the viewer use (SolverSettings{}: 1e-4), the chapters
// solve to different errors (warm start, another preconditioner): they drift apart, but
// boundedly. Over kDefaultToleranceSteps steps of the driven scene the drift must stay below
// kDefaultToleranceDrift = 10 x the tolerance, relative to the motion: the chapters that
// start from a guess or precondition otherwise (06 on) drift by the order of the tolerance;
// 02 to 05 run Eigen's CG from zero like chapter 01 and differ only by rounding.
constexpr int kDefaultToleranceSteps = 100;
constexpr double kDefaultToleranceDrift = 1e-3;
inline void check_drift_at_default_tolerance(const std::string& chapter) {
  const Scene scene = driven_scene();
  const Drift d = drift_from_ch01(chapter, scene, kDefaultToleranceSteps, SolverSettings{});
  INFO(chapter << " at tolerance " << SolverSettings{}.tolerance << " over "
               << kDefaultToleranceSteps << " steps: max |dx| " << d.x << " of motion " << d.motion
               << ", max |dv| " << d.v << " of speed " << d.speed << ", relative " << d.relative());
  REQUIRE(d.motion > 1e-3);
  CHECK(d.relative() < kDefaultToleranceDrift);
}

}  // namespace fem::test

// Allocation tests skip (and say so) where the counter is off: the sanitizer builds.
#define FEM_REQUIRE_ALLOCATION_COUNTER()                       \
  if (!fem::alloc::enabled()) {                                \
    SUCCEED("allocation counting is off in sanitizer builds"); \
    return;                                                    \
  }

// The tests every chapter after 01 runs, generic over the chapter: equivalence with chapter
// 01 on the driven scene (on the other two: tests/generic), the damping rate, and the drift
// at the default tolerance. A new chapter's test file starts with
// FEM_CHAPTER_TESTS("NN", "[chNN]").
#define FEM_CHAPTER_TESTS(ID, TAG)                                                                 \
  TEST_CASE("ch" ID ": matches chapter 01 on the driven scene, every filter case moving", TAG) {   \
    fem::test::check_matches_ch01_on_driven_scene(ID);                                             \
  }                                                                                                \
  TEST_CASE("ch" ID ": mass damping slows a rigid translation by 1/(1 + h alpha) per step", TAG) { \
    fem::test::check_damping_rate(ID);                                                             \
  }                                                                                                \
  TEST_CASE("ch" ID ": drift from chapter 01 at the default tolerance stays bounded", TAG) {       \
    fem::test::check_drift_at_default_tolerance(ID);                                               \
  }

#include <random>

#include "common/model.hpp"
#include "common/threads.hpp"

namespace fem::test {

// The mouse of the soak tests: a spring on a random surface node, pulling towards a random
// point near the node's rest position, that jumps to another node every `hold` steps. Stiff
// enough to pull the body around (its weight over 5 cm). The same seed gives every chapter
// the same sequence of nodes and targets.
class JumpingMouse {
 public:
  JumpingMouse(const Scene& scene, int hold) : X_(scene.mesh.X), hold_(hold) {
    for (const auto& t : scene.mesh.boundary)
      for (int a = 0; a < 3; ++a) surface_.push_back(t[a]);
    std::sort(surface_.begin(), surface_.end());
    surface_.erase(std::unique(surface_.begin(), surface_.end()), surface_.end());
    stiffness_ = Model(scene).lumped_mass.sum() / 3.0 * 9.81 / 0.05;
    pick_ = std::uniform_int_distribution<std::size_t>(0, surface_.size() - 1);
  }
  // The spring's force on the state before step k (a new node and target when k % hold == 0).
  std::vector<ExternalForce> force(int k, const State& state) {
    if (k % hold_ == 0) {
      node_ = surface_[pick_(random_)];
      target_ =
          X_.col(node_) + Eigen::Vector3d(offset_(random_), offset_(random_), offset_(random_));
    }
    return {{node_, stiffness_ * (target_ - state.x.segment<3>(3 * node_))}};
  }
  // Step k is one of the first `steps` steps after a jump.
  bool just_jumped(int k, int steps) const { return k > 0 && k % hold_ < steps; }

 private:
  Eigen::Matrix3Xd X_;
  int hold_;
  std::vector<int> surface_;
  double stiffness_ = 0.0;
  std::mt19937 random_{2026};
  std::uniform_int_distribution<std::size_t> pick_;
  std::uniform_real_distribution<double> offset_{-0.15, 0.15};
  int node_ = 0;
  Eigen::Vector3d target_ = Eigen::Vector3d::Zero();
};

// The soak tests' loop: `steps` steps of `stepper` from `state` under the jumping mouse, ended
// by the first step that diverges (common/stepper.hpp's divergence: its reason is returned, ""
// when none does); after every other step `each(k)` records what the test asserts.
template <class Stepper, class Each>
std::string soak_under_mouse(Stepper& stepper, JumpingMouse& mouse, State& state, int steps,
                             Each&& each) {
  for (int k = 0; k < steps; ++k) {
    stepper.set_external_forces(mouse.force(k, state));
    stepper.step(state);
    if (const char* why = divergence(state, stepper.profile())) return why;
    each(k);
  }
  return "";
}

// A soak of a threaded chapter's stepper S: `steps` steps from rest under the jumping mouse (a
// new node every 7 steps) on `threads` threads, its adaptive team off so that it really runs
// on that many; what the soak tests assert of it.
struct Soak {
  State state;
  int not_converged = 0;
  std::string diverged;
  double max_speed_early = 0.0, max_speed = 0.0;  // over the first 300 steps, and over all
};
template <class S>
Soak soak_run(const Scene& scene, int threads, int steps) {
  const ThreadCountScope scope(threads);
  S stepper(scene, {});
  stepper.team().adaptive_team().set_enabled(false);
  JumpingMouse mouse(scene, 7);
  Soak out;
  out.state = rest_state(scene);
  out.diverged = soak_under_mouse(stepper, mouse, out.state, steps, [&](int k) {
    out.not_converged += stepper.profile().converged ? 0 : 1;
    out.max_speed = std::max(out.max_speed, out.state.v.cwiseAbs().maxCoeff());
    if (k < 300) out.max_speed_early = out.max_speed;
  });
  return out;
}

// The soak tests of a threaded chapter's stepper S: 2,000 steps (soak_steps) on 1 and 2 threads.
// Every solve converges, no step diverges, the motion stays bounded (damping takes out what the
// spring puts in), and the two thread counts give the same bits.
template <class S>
void check_soak(const Scene& scene) {
  const int steps = soak_steps(2000);
  const Soak one = soak_run<S>(scene, 1, steps);
  const Soak two = soak_run<S>(scene, openmp_enabled() ? 2 : 1, steps);
  for (const Soak* run : {&one, &two}) {
    CHECK(run->diverged.empty());
    CHECK(run->not_converged == 0);
    CHECK(run->max_speed_early > 0.0);
    CHECK(run->max_speed < 10.0 * run->max_speed_early);
  }
  CHECK((one.state.x.array() == two.state.x.array()).all());
  CHECK((one.state.v.array() == two.state.v.array()).all());
}

}  // namespace fem::test
