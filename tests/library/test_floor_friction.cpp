// The floor's Coulomb friction (femcourse/simulator.hpp, set_floor): on a slope of 20 degrees
// (tan 20 = 0.36) a body lands and slides down without friction, slides slower with a
// coefficient below the slope's tangent, and stays where it landed with one above it; a stuck
// contact's reaction stays inside the friction cone; the coefficient is checked and saved.
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "common/model.hpp"
#include "femcourse/simulator.hpp"
#include "support.hpp"
#include "test_beam.hpp"

namespace {

using femcourse::Body;
using femcourse::BodyDescription;

const double kSlope = 20.0 * 3.14159265358979323846 / 180.0;
const Eigen::Vector3d kNormal(std::sin(kSlope), 0.0, std::cos(kSlope));

// The test beam, free, with some mass damping (as the library's floor tests).
BodyDescription free_beam() {
  BodyDescription d = fem::test::clamped_beam_description();
  d.constraints.clear();
  d.damping_alpha = 2.0;
  return d;
}

Eigen::Vector3d centroid(const Body& body) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int i = 0; i < body.num_nodes(); ++i)
    sum += Eigen::Map<const Eigen::Vector3d>(body.positions() + 3 * i);
  return sum / body.num_nodes();
}

// Gravity's direction along the slope, downhill.
Eigen::Vector3d downhill() {
  const Eigen::Vector3d down(0.0, 0.0, -1.0);
  return (down - down.dot(kNormal) * kNormal).normalized();
}

// The slope 2 cm under the body's lowest point (along its normal), with `friction`.
void set_slope(Body& body, double friction) {
  double lowest = std::numeric_limits<double>::infinity();
  for (int i = 0; i < body.num_nodes(); ++i)
    lowest =
        std::min(lowest, kNormal.dot(Eigen::Map<const Eigen::Vector3d>(body.positions() + 3 * i)));
  const Eigen::Vector3d point = (lowest - 0.02) * kNormal;
  body.set_floor({point[0], point[1], point[2]}, {kNormal[0], kNormal[1], kNormal[2]}, friction);
}

// How far downhill the body's centroid moves in 0.5 s (50 steps of 10 ms) once it has landed
// (40 steps: it falls 2 cm, one end first, and friction stops what the fall gave it).
double slide(double friction) {
  Body body(free_beam());
  set_slope(body, friction);
  for (int k = 0; k < 40; ++k) body.step();
  REQUIRE(body.floor_contacts().size() > 40);
  const Eigen::Vector3d landed = centroid(body);
  for (int k = 0; k < 50; ++k) body.step();
  return (centroid(body) - landed).dot(downhill());
}

}  // namespace

TEST_CASE("friction slows a slide and holds a body on a slope it can hold", "[library]") {
  const double free = slide(0.0), kinetic = slide(0.2), stuck = slide(0.8);
  INFO("downhill in 0.5 s once landed: " << free << " m frictionless, " << kinetic << " m at 0.2, "
                                         << stuck << " m at 0.8");
  // Frictionless the slope accelerates it at g sin 20 = 3.4 m/s^2 (less the mass damping); at
  // 0.2 at g (sin 20 - 0.2 cos 20) = 1.5 m/s^2; at 0.8 (over tan 20) it stays, but for a creep
  // (a contact's position moves with the step's velocity before friction takes it: 1 mm).
  CHECK(free > 0.3);
  CHECK(kinetic > 0.1 * free);
  CHECK(kinetic < 0.7 * free);
  CHECK(std::abs(stuck) < 0.005);
}

TEST_CASE("a stuck contact's reaction stays inside the friction cone", "[library]") {
  Body body(free_beam());
  const double friction = 0.8;
  set_slope(body, friction);
  for (int k = 0; k < 90; ++k) body.step();
  const femcourse::BodyState state = body.save_state();
  REQUIRE_FALSE(state.floor_stuck.empty());
  CHECK(state.floor_friction == friction);
  body.step();
  const std::vector<int> stuck = body.save_state().floor_stuck;  // still stuck after the step
  int held = 0, inside = 0;
  for (const femcourse::NodeForce& r : body.reactions()) {
    if (!std::binary_search(stuck.begin(), stuck.end(), r.node)) continue;
    const Eigen::Vector3d f(r.force[0], r.force[1], r.force[2]);
    const double push = f.dot(kNormal), along = (f - push * kNormal).norm();
    ++held;
    CHECK(push > 0.0);
    if (along <= friction * push * (1.0 + 1e-9)) ++inside;
  }
  CHECK(held > 10);
  CHECK(inside == held);
}

TEST_CASE("a body restored with stuck contacts steps as the one that saved them", "[library]") {
  Body body(free_beam());
  set_slope(body, 0.8);
  for (int k = 0; k < 60; ++k) body.step();
  const femcourse::BodyState saved = body.save_state();
  for (int k = 0; k < 10; ++k) body.step();
  Body restored(free_beam());  // no floor of its own: the state brings it, friction included
  restored.restore_state(saved);
  for (int k = 0; k < 10; ++k) restored.step();
  CHECK(
      std::equal(body.positions(), body.positions() + 3 * body.num_nodes(), restored.positions()));
  CHECK(restored.save_state().floor_stuck == body.save_state().floor_stuck);
}

TEST_CASE("a negative or non-finite friction, or a stuck node off the floor, is refused",
          "[library]") {
  Body body(free_beam());
  for (const double bad : {-0.1, std::nan(""), std::numeric_limits<double>::infinity()})
    CHECK_THROWS_WITH(body.set_floor({0, 0, -1}, {0, 0, 1}, bad),
                      fem::test::contains_text("friction coefficient"));
  femcourse::BodyState state = body.save_state();
  state.floor = true;
  state.floor_stuck = {3};
  CHECK_THROWS_WITH(body.restore_state(state),
                    fem::test::contains_text("not among the floor contacts"));
  state.floor_contacts = {3};
  state.floor_stuck = {3, 3};
  CHECK_THROWS_WITH(body.restore_state(state), fem::test::contains_text("twice"));
  state.floor_stuck = {3};
  state.floor_friction = -1.0;
  CHECK_THROWS_WITH(body.restore_state(state), fem::test::contains_text("friction"));
}
