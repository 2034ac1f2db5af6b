// The library while an app runs it (femcourse/simulator.hpp): grab, drag, release, the
// one-sided floor, the surface and the forces out, a failed call that changes nothing, warnings
// to the caller, a saved state restored exactly, the deformation watch.
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cstring>
#include <iostream>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "common/model.hpp"
#include "common/stepper.hpp"
#include "femcourse/simulator.hpp"
#include "support.hpp"
#include "test_beam.hpp"

namespace {

using femcourse::Body;
using femcourse::BodyDescription;

// The test beam (nodes at min x clamped, gravity -z) as arrays.
BodyDescription beam(const std::string& chapter = "") {
  BodyDescription d = fem::test::clamped_beam_description();
  d.chapter = chapter;
  return d;
}

std::vector<double> positions_of(const Body& body) {
  return {body.positions(), body.positions() + 3 * body.num_nodes()};
}

// The nodes at the largest x: the free end.
std::vector<int> tip_nodes(const Body& body) {
  double x_max = -1e300;
  for (int i = 0; i < body.num_nodes(); ++i) x_max = std::max(x_max, body.position(i)[0]);
  std::vector<int> tip;
  for (int i = 0; i < body.num_nodes(); ++i)
    if (body.position(i)[0] > x_max - 1e-9) tip.push_back(i);
  return tip;
}

double lowest_z(const Body& body) {
  double z = 1e300;
  for (int i = 0; i < body.num_nodes(); ++i) z = std::min(z, body.position(i)[2]);
  return z;
}

void steps(Body& body, int n) {
  for (int k = 0; k < n; ++k) body.step();
}

}  // namespace

TEST_CASE("a chapter's stepper refuses to change its constraints, saying so", "[library]") {
  const fem::Scene scene = fem::test::test_scene("cantilever");
  const auto stepper = fem::make_stepper("01", scene);
  CHECK_FALSE(stepper->can_change_constraints());
  CHECK_THROWS_WITH(stepper->set_constraints({}),
                    "this chapter's stepper cannot change its constraints while it runs");
}

TEST_CASE("after a refused set_forces, set_chapter keeps the force and says the chapter",
          "[library]") {
  Body reference(beam()), body(beam());
  const int tip = tip_nodes(body).front();
  for (Body* b : {&reference, &body}) b->set_forces({{tip, {0.0, 0.0, -2.0}}});
  CHECK_THROWS_AS(body.set_forces({{100000, {1.0, 0.0, 0.0}}}), std::invalid_argument);
  for (Body* b : {&reference, &body}) {
    steps(*b, 3);
    b->set_chapter("10");
    steps(*b, 3);
  }
  CHECK(body.chapter() == fem::find_chapter("10").id);
  CHECK(positions_of(body) == positions_of(reference));
}

TEST_CASE("every throwing call leaves the body exactly as it was", "[library]") {
  Body twin(beam()), body(beam());
  steps(twin, 2);
  steps(body, 2);
  femcourse::BodyState wrong;
  wrong.positions.assign(6, 0.0);
  wrong.velocities.assign(6, 0.0);
  fem::State short_state = body.state();
  short_state.x.conservativeResize(3);
  CHECK_THROWS_AS(body.set_forces({{0, {0.0, std::numeric_limits<double>::infinity(), 0.0}}}),
                  std::invalid_argument);
  CHECK_THROWS_AS(body.set_chapter("99_nothing"), std::invalid_argument);
  CHECK_THROWS_AS(body.grab({-1}), std::invalid_argument);
  CHECK_THROWS_AS(body.set_floor({0, 0, 0}, {0, 0, 0}), std::invalid_argument);
  CHECK_THROWS_AS(body.restore_state(wrong), std::invalid_argument);
  CHECK_THROWS_AS(body.set_threads(-1), std::invalid_argument);
  CHECK_THROWS_AS(body.set_state(short_state), std::invalid_argument);
  CHECK_THROWS_AS(body.position(-1), std::out_of_range);
  CHECK(body.grabbed().empty());
  CHECK(body.chapter() == twin.chapter());
  steps(twin, 3);
  steps(body, 3);
  CHECK(positions_of(body) == positions_of(twin));
}

TEST_CASE("a moved-from body throws std::logic_error instead of crashing", "[library]") {
  Body from(beam());
  Body to(std::move(from));
  CHECK_THROWS_AS(from.num_nodes(), std::logic_error);  // NOLINT(bugprone-use-after-move)
  CHECK_THROWS_AS(from.step(), std::logic_error);
  CHECK_THROWS_WITH(from.positions(), fem::test::contains_text("moved from"));
  to.step();
  from = Body(beam());
  CHECK_NOTHROW(from.step());
}

TEST_CASE("warnings go to the caller's handler or queue, not to stderr", "[library]") {
  BodyDescription d = beam();
  d.solver_tolerance = 1e-14;  // unreachable: the solve stops at its cap, still a step
  d.solver_max_iterations = 5;
  Body body(d);
  std::ostringstream captured;
  std::streambuf* const cerr = std::cerr.rdbuf(captured.rdbuf());
  body.step();
  std::cerr.rdbuf(cerr);
  CHECK(captured.str().empty());
  const std::vector<std::string> queued = body.take_warnings();
  REQUIRE(queued.size() == 1);
  CHECK(queued[0].find("iteration cap") != std::string::npos);
  CHECK(body.take_warnings().empty());
  std::vector<std::string> handled;
  Body other(d);
  other.set_warning_handler([&](const std::string& w) { handled.push_back(w); });
  other.step();
  CHECK(handled.size() == 1);
  CHECK(other.take_warnings().empty());
}

TEST_CASE("a diverged step's message names what the caller can change", "[library]") {
  BodyDescription d = beam();
  d.youngs_modulus = 1e306;
  Body body(d);
  try {
    body.step();
    FAIL("an overflowing step went through");
  } catch (const femcourse::StepDiverged& e) {
    const std::string what = e.what();
    CHECK(what.find("youngs_modulus") != std::string::npos);
    CHECK(what.find("--") == std::string::npos);
  }
}

TEST_CASE("a restored state steps bit-identically to the run that saved it", "[library]") {
  Body body(beam());
  body.set_forces({{tip_nodes(body).front(), {0.0, 3.0, -1.0}}});
  steps(body, 7);
  const femcourse::BodyState saved = body.save_state();
  steps(body, 9);
  Body restored(beam());
  restored.set_forces({{tip_nodes(body).front(), {0.0, 3.0, -1.0}}});
  steps(restored, 2);  // another history: its stepper's hidden state differs
  restored.restore_state(saved);
  steps(restored, 9);
  CHECK(positions_of(restored) == positions_of(body));
  CHECK(restored.time() == body.time());
}

TEST_CASE("the deformation watch flags a 1e30 N force, not an ordinary swing", "[library]") {
  Body swing(beam());
  steps(swing, 20);
  CHECK(swing.check_deformation().plausible);
  Body blown(beam());
  blown.set_forces({{tip_nodes(blown).front(), {0.0, 0.0, 1e30}}});
  try {
    steps(blown, 2);
  } catch (const femcourse::StepDiverged&) {
  }
  const femcourse::DeformationStatus status = blown.check_deformation();
  CHECK_FALSE(status.plausible);
  CHECK(status.largest_stretch > 5.0);
}

TEST_CASE("the surface is the closed, outward boundary of the body", "[library]") {
  const Body body(beam());
  const fem::Scene& scene = body.scene();
  REQUIRE(!body.surface().empty());
  // Divergence theorem: the outward triangles enclose the tetrahedra's volume.
  double enclosed = 0.0, volume = 0.0;
  for (const auto& t : body.surface()) {
    const Eigen::Vector3d a = scene.mesh.X.col(t[0]), b = scene.mesh.X.col(t[1]),
                          c = scene.mesh.X.col(t[2]);
    enclosed += a.dot(b.cross(c)) / 6.0;
  }
  for (const auto& t : scene.mesh.tets) {
    Eigen::Matrix3d Dm;
    for (int i = 0; i < 3; ++i) Dm.col(i) = scene.mesh.X.col(t[i + 1]) - scene.mesh.X.col(t[0]);
    volume += Dm.determinant() / 6.0;
  }
  CHECK(enclosed == Approx(volume).epsilon(1e-10));
}

TEST_CASE("the supports' reactions carry the body's weight at rest", "[library]") {
  BodyDescription d = beam();
  d.youngs_modulus = 1e7;
  d.damping_alpha = 20.0;
  Body body(d);
  steps(body, 150);
  double weight = 0.0, lifted = 0.0;
  for (const auto& r : body.reactions()) lifted += r.force[2];
  // The lumped masses sum to rho V; gravity pulls -z.
  const fem::Model model(body.scene());
  weight = model.lumped_mass.sum() / 3.0 * 9.81;
  CHECK(lifted == Approx(weight).epsilon(1e-3));
  CHECK(body.reactions().size() == body.scene().constraints.size());
}

TEST_CASE("grab, drag and release equal rebuilding the body with those constraints", "[library]") {
  // The body changes its stepper's constraints in place (the last chapter can): the solver's
  // warm start and the hierarchy carry over, so the motion equals the rebuilt bodies' to the
  // solver's tolerance, not to the bit; the grabbed nodes follow their velocity exactly.
  const BodyDescription d = beam();
  Body body(d);
  const std::vector<int> tip = tip_nodes(body);
  steps(body, 3);
  const double z0 = body.position(tip[0])[2];
  body.grab(tip, {0.0, 0.0, 0.5});
  steps(body, 10);
  CHECK(body.position(tip[0])[2] == Approx(z0 + 10 * d.time_step * 0.5));
  body.release();
  steps(body, 5);
  // The same by hand: a body per phase, the state carried over.
  Body first(d);
  steps(first, 3);
  BodyDescription held = d;
  for (const int n : tip)
    held.constraints.push_back({n, femcourse::Constraint::Kind::Fixed, {}, {0.0, 0.0, 0.5}});
  Body second(held);
  second.set_state(first.state());
  steps(second, 10);
  Body third(d);
  third.set_state(second.state());
  steps(third, 5);
  CHECK(body.changes_constraints_in_place());
  const std::vector<double> ours = positions_of(body), rebuilt = positions_of(third);
  REQUIRE(ours.size() == rebuilt.size());
  double worst = 0.0;
  for (std::size_t k = 0; k < ours.size(); ++k)
    worst = std::max(worst, std::abs(ours[k] - rebuilt[k]));
  INFO("largest difference " << worst << " m");
  CHECK(worst < 1e-5);  // the beam is 1 m long: 10 um, the CG tolerance's order
  CHECK(body.grabbed().empty());
}

TEST_CASE("the floor holds a falling body and lets it go when lifted", "[library]") {
  BodyDescription d = beam();
  d.constraints.clear();  // it falls
  d.damping_alpha = 2.0;
  Body body(d);
  const double floor = lowest_z(body) - 0.02;
  body.set_floor({0.0, 0.0, floor}, {0.0, 0.0, 1.0});
  steps(body, 60);
  CHECK(lowest_z(body) >= floor - 1e-12);
  CHECK(!body.floor_contacts().empty());
  // A floor pushes only: every reaction at a contact points up.
  for (const auto& r : body.reactions()) CHECK(r.force[2] > -1e-9);
  // Pulled up by forces above its weight, it leaves the floor (a two-sided plane would not).
  std::vector<femcourse::NodeForce> lift;
  for (int i = 0; i < body.num_nodes(); ++i) lift.push_back({i, {0.0, 0.0, 5.0}});
  body.set_forces(lift);
  steps(body, 30);
  CHECK(body.floor_contacts().empty());
  CHECK(lowest_z(body) > floor + 1e-3);
}

TEST_CASE("two bodies with their own thread counts step at once as each alone", "[library]") {
  BodyDescription one = beam("13"), two = beam("13");
  one.threads = 1;
  two.threads = 2;
  Body alone(one);
  steps(alone, 10);
  Body a(one), b(two);
  std::thread other([&] { steps(b, 10); });
  steps(a, 10);
  other.join();
  CHECK(positions_of(a) == positions_of(alone));
  CHECK(positions_of(b) == positions_of(alone));
  CHECK(b.threads() == 2);
}
