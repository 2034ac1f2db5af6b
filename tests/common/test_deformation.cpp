// The deformation check of fem_sim (common/deformation.hpp): silent on the course's own
// scenes, a warning where a step is in trouble (inverted elements that persist, a blown-up
// element, energy that grows).
#include <Eigen/Geometry>

#include "common/deformation.hpp"
#include "support.hpp"

using namespace fem;

namespace {

// The scene with the course's default material, time step and damping (fem_sim's defaults).
Scene course_scene(double youngs_modulus = Material{}.youngs_modulus, double dt = Scene{}.dt) {
  Material m;
  m.youngs_modulus = youngs_modulus;
  Scene scene = make_scene("cantilever", test::test_mesh(), m);
  scene.dt = dt;
  return scene;
}

// Runs chapter 01 for `steps` steps through the check; returns the steps in trouble.
int troubled_steps(const Scene& scene, int steps) {
  auto stepper = make_stepper("01", scene, SolverSettings{});
  State state = rest_state(scene);
  const DeformationProbe probe(scene);
  DeformationReport report;
  for (int k = 1; k <= steps; ++k) {
    stepper->step(state);
    report.after_step(k, probe.check(state));
  }
  return report.troubled_steps();
}

}  // namespace

TEST_CASE("deformation check: silent on the default cantilever and the regime sweep's ends",
          "[deformation]") {
  CHECK(troubled_steps(course_scene(), 200) == 0);
  CHECK(troubled_steps(course_scene(1e3), 18) == 0);  // the sweep's softest body
  CHECK(troubled_steps(course_scene(3e7), 18) == 0);  // and its stiffest
}

// At a tiny step the body's energy is far below the round-off of gravity's potential (a node
// moves by less than its coordinates' last digit), which once read as growth: a false
// "unstable; try a smaller --dt" at --dt 1e-12.
TEST_CASE("deformation check: silent at tiny time steps, where the energy is round-off",
          "[deformation]") {
  for (const double dt : {1e-8, 1e-12, 1e-20, 1e-300})
    CHECK(troubled_steps(course_scene(Material{}.youngs_modulus, dt), 5) == 0);
}

TEST_CASE("deformation check: a step far too large is reported", "[deformation]") {
  CHECK(troubled_steps(course_scene(1e3, 0.5), 20) > 0);
}

TEST_CASE("deformation check: a body turned rigidly is no trouble, a stretched one is",
          "[deformation]") {
  const Scene scene = course_scene();
  const DeformationProbe probe(scene);
  State state = rest_state(scene);
  // Half a turn about the clamped end: every node moves up to twice the body's length.
  const Eigen::Matrix3d R = Eigen::AngleAxisd(3.14159265358979, Eigen::Vector3d::UnitY()).matrix();
  for (int i = 0; i < scene.mesh.num_nodes(); ++i)
    state.x.segment<3>(3 * i) = R * scene.mesh.X.col(i);
  DeformationCheck turned = probe.check(state);
  CHECK(turned.inverted == 0);
  CHECK(turned.largest_stretch == Approx(1.0).epsilon(1e-9));
  for (int i = 0; i < scene.mesh.num_nodes(); ++i) state.x[3 * i] *= 6.0;  // 6 times as long
  const DeformationCheck stretched = probe.check(state);
  CHECK(stretched.largest_stretch > 5.0);
  CHECK(stretched.energy_content > 0.0);
}

TEST_CASE("deformation report: what persists or grows, not what passes", "[deformation]") {
  DeformationCheck one_inverted;
  one_inverted.elements = 5934;
  one_inverted.inverted = 1;  // the default scene on the plate: one element, for 19 steps
  DeformationReport report;
  for (int k = 1; k <= 49; ++k) CHECK_FALSE(report.after_step(k, one_inverted));
  CHECK(report.after_step(50, one_inverted));  // for 50 steps: it does not recover
  DeformationCheck share = one_inverted;
  share.inverted = 100;  // over 1% of the body
  DeformationReport folding;
  CHECK_FALSE(folding.after_step(1, share));
  CHECK_FALSE(folding.after_step(2, share));
  CHECK(folding.after_step(3, share));
  DeformationCheck energy;
  energy.energy_content = 100.0;
  energy.energy = -20.0;  // below rest: gravity's work taken by damping
  DeformationReport growing;
  CHECK_FALSE(growing.after_step(1, energy));
  energy.energy = 6.0;  // 6% of the content above rest, from nowhere
  CHECK(growing.after_step(2, energy));
  CHECK(growing.troubled_steps() == 1);
}
