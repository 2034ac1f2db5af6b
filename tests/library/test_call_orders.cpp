// The library's calls in the orders an app may make them (issue 65): read-outs before any
// step, the same call twice, every call after a refused one, on a moved-from body, after a
// diverged step, an empty force list or grab, the floor's friction across a chapter switch.
// Each case says what a user expects: the documented result, bit for bit where the contract
// promises it, and never a NaN passed off as a plausible state.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "femcourse/simulator.hpp"
#include "support.hpp"
#include "test_beam.hpp"

namespace {

using femcourse::Body;
using femcourse::BodyDescription;
using femcourse::NodeForce;

BodyDescription beam() { return fem::test::clamped_beam_description(); }

// The beam, free, on a floor 1 cm under its lowest node with `friction`, after 20 steps; its
// floor's height in `floor`.
Body landed_beam(double friction, double& floor) {
  BodyDescription d = beam();
  d.constraints.clear();
  Body body(d);
  double lowest = 1e300;
  for (int i = 0; i < body.num_nodes(); ++i) lowest = std::min(lowest, body.position(i)[2]);
  floor = lowest - 0.01;
  body.set_floor({0.0, 0.0, floor}, {0.0, 0.0, 1.0}, friction);
  for (int k = 0; k < 20; ++k) body.step();
  return body;
}

std::vector<double> positions_of(const Body& body) {
  return {body.positions(), body.positions() + 3 * body.num_nodes()};
}

// The positions after `steps` steps of a body made from `d` with nothing else done to it.
std::vector<double> plain_run(const BodyDescription& d, int steps) {
  Body body(d);
  for (int k = 0; k < steps; ++k) body.step();
  return positions_of(body);
}

bool all_finite(const std::vector<double>& v) {
  for (const double x : v)
    if (!std::isfinite(x)) return false;
  return true;
}

// The node with the largest x (the free end's corner).
int tip(const Body& body) {
  int best = 0;
  for (int i = 1; i < body.num_nodes(); ++i)
    if (body.positions()[3 * i] > body.positions()[3 * best]) best = i;
  return best;
}

}  // namespace

TEST_CASE("call orders: every read-out before the first step", "[library]") {
  Body body(beam());
  const std::vector<double>& elastic = body.elastic_forces();
  REQUIRE(elastic.size() == static_cast<std::size_t>(3 * body.num_nodes()));
  for (const double f : elastic) CHECK(std::abs(f) < 1e-9);  // at rest: no elastic force
  for (const NodeForce& r : body.reactions()) {
    CHECK(r.node >= 0);
    CHECK(r.node < body.num_nodes());
    CHECK(all_finite({r.force.begin(), r.force.end()}));
  }
  const femcourse::DeformationStatus status = body.check_deformation();
  CHECK(status.plausible);
  CHECK(status.inverted_elements == 0);
  CHECK(status.largest_stretch == Approx(1.0));
  CHECK(body.threads_used() == 0);
  CHECK(body.time() == 0.0);
  CHECK(body.profile().iterations == 0);
  CHECK(body.grabbed().empty());
  CHECK(body.floor_contacts().empty());
  CHECK(body.take_warnings().empty());
}

TEST_CASE("call orders: interaction calls before the first step that undo each other",
          "[library]") {
  const std::vector<double> plain = plain_run(beam(), 3);
  Body body(beam());
  body.set_floor({0.0, 0.0, -10.0}, {0.0, 0.0, 1.0}, 0.5);
  body.remove_floor();
  body.grab({});
  body.release();
  body.set_forces({});
  body.set_chapter(body.chapter());
  body.set_threads(1);
  body.set_threads(0);
  for (int k = 0; k < 3; ++k) body.step();
  CHECK(positions_of(body) == plain);
}

TEST_CASE("call orders: save_state before the first step, restored after steps", "[library]") {
  Body body(beam());
  const femcourse::BodyState rest = body.save_state();
  CHECK(rest.steps == 0);
  CHECK_FALSE(rest.floor);
  for (int k = 0; k < 3; ++k) body.step();
  body.restore_state(rest);
  CHECK(body.time() == 0.0);
  CHECK(positions_of(body) == beam().rest_positions);
  for (int k = 0; k < 3; ++k) body.step();
  CHECK(positions_of(body) == plain_run(beam(), 3));
}

TEST_CASE("call orders: the read-outs twice in a row give the same, in the same storage",
          "[library]") {
  Body body(beam());
  body.set_floor({0.0, 0.0, -0.05}, {0.0, 0.0, 1.0});
  for (int k = 0; k < 5; ++k) body.step();
  const std::vector<double>& e1 = body.elastic_forces();
  const std::vector<double> copy1 = e1;
  const std::vector<double>& e2 = body.elastic_forces();
  CHECK(&e1 == &e2);
  CHECK(e2 == copy1);
  const std::vector<NodeForce> r1 = body.reactions();
  const std::vector<NodeForce>& r2 = body.reactions();
  REQUIRE(r1.size() == r2.size());
  for (std::size_t i = 0; i < r1.size(); ++i) {
    CHECK(r1[i].node == r2[i].node);
    CHECK(r1[i].force == r2[i].force);
  }
  CHECK(body.check_deformation().largest_stretch == body.check_deformation().largest_stretch);
}

TEST_CASE("call orders: save_state twice, restore_state twice", "[library]") {
  Body body(beam());
  for (int k = 0; k < 4; ++k) body.step();
  const femcourse::BodyState a = body.save_state();
  const femcourse::BodyState b = body.save_state();
  CHECK(a.positions == b.positions);
  CHECK(a.velocities == b.velocities);
  CHECK(a.steps == b.steps);
  for (int k = 0; k < 4; ++k) body.step();
  const std::vector<double> once = positions_of(body);
  body.restore_state(a);
  body.restore_state(a);
  for (int k = 0; k < 4; ++k) body.step();
  CHECK(positions_of(body) == once);
}

TEST_CASE("call orders: the read-outs follow restore_state, not the state before it", "[library]") {
  Body body(beam());
  for (int k = 0; k < 5; ++k) body.step();
  const std::vector<double> elastic5 = body.elastic_forces();
  const double stretch5 = body.check_deformation().largest_stretch;
  const femcourse::BodyState saved = body.save_state();
  for (int k = 0; k < 5; ++k) body.step();
  REQUIRE(body.elastic_forces() != elastic5);  // read at step 10: cached for that state
  body.restore_state(saved);
  CHECK(body.elastic_forces() == elastic5);
  CHECK(body.check_deformation().largest_stretch == stretch5);
}

TEST_CASE("call orders: a refused call changes nothing, and the next steps show it", "[library]") {
  const std::vector<double> plain = plain_run(beam(), 3);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  Body body(beam());
  const int n = body.num_nodes();
  CHECK_THROWS_AS(body.set_floor({0.0, 0.0, -0.01}, {0.0, 0.0, 1.0}, -0.5), std::invalid_argument);
  CHECK_THROWS_AS(body.set_floor({0.0, 0.0, -0.01}, {0.0, 0.0, 1.0}, nan), std::invalid_argument);
  CHECK_THROWS_AS(body.grab({0, n}, {0.0, 0.0, 1.0}), std::invalid_argument);
  body.move_grabbed({0.0, 0.0, 5.0});  // nothing grabbed: the refused grab took nothing
  CHECK_THROWS_AS(body.set_chapter("99"), std::invalid_argument);
  CHECK_THROWS_AS(body.set_threads(-1), std::invalid_argument);
  CHECK_THROWS_AS(body.set_forces({{n, {1.0, 0.0, 0.0}}}), std::invalid_argument);
  femcourse::BodyState wrong = body.save_state();
  wrong.positions.pop_back();
  CHECK_THROWS_AS(body.restore_state(wrong), std::invalid_argument);
  CHECK(body.grabbed().empty());
  CHECK(body.threads() == 0);
  for (int k = 0; k < 3; ++k) body.step();
  CHECK_FALSE(body.save_state().floor);
  CHECK(positions_of(body) == plain);
}

TEST_CASE("call orders: a refused set_forces keeps the forces given before it", "[library]") {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  Body reference(beam());
  const int node = tip(reference);
  reference.set_forces({{node, {0.0, 0.0, 2.0}}});
  Body body(beam());
  body.set_forces({{node, {0.0, 0.0, 2.0}}});
  CHECK_THROWS_AS(body.set_forces({{node, {nan, 0.0, 0.0}}}), std::invalid_argument);
  for (int k = 0; k < 3; ++k) {
    reference.step();
    body.step();
  }
  CHECK(positions_of(body) == positions_of(reference));
}

TEST_CASE("call orders: an empty force list after forces removes them", "[library]") {
  Body body(beam());
  body.set_forces({{tip(body), {0.0, 0.0, 50.0}}});
  body.set_forces({});
  for (int k = 0; k < 3; ++k) body.step();
  CHECK(positions_of(body) == plain_run(beam(), 3));
}

TEST_CASE("call orders: a grab of zero nodes replaces the grab before it", "[library]") {
  Body body(beam());
  const int node = tip(body);
  body.grab({node}, {0.0, 0.0, 1.0});
  body.step();
  body.grab({});
  CHECK(body.grabbed().empty());
  body.move_grabbed({0.0, 0.0, 1.0});  // nothing held: no effect
  const double z = body.position(node)[2];
  for (int k = 0; k < 3; ++k) body.step();
  CHECK(body.position(node)[2] < z + 0.02);  // not driven up at 1 m/s (3 cm in 3 steps)
}

TEST_CASE("call orders: grab, then the floor, then release: the node can rest on the floor",
          "[library]") {
  Body body(beam());
  const int node = tip(body);
  body.grab({node}, {0.0, 0.0, -1.0});
  body.set_floor({0.0, 0.0, body.position(node)[2] - 0.015}, {0.0, 0.0, 1.0});
  for (int k = 0; k < 3; ++k) body.step();
  CHECK(body.position(node)[2] < body.position(node)[2] + 1.0);  // finite
  const std::vector<int>& contacts = body.floor_contacts();
  CHECK(std::find(contacts.begin(), contacts.end(), node) == contacts.end());  // grabbed
  body.release();
  for (int k = 0; k < 3; ++k) body.step();
  CHECK(all_finite(positions_of(body)));
}

TEST_CASE("call orders: the read-outs after a diverged step say what the body holds", "[library]") {
  Body body(beam());
  const femcourse::BodyState good = body.save_state();
  // A force that overflows the solve: the step is refused and the body keeps a finite state,
  // which the read-outs describe (no NaN stretch, no reaction of the refused step).
  body.set_forces({{tip(body), {0.0, 0.0, 1e300}}});
  CHECK_THROWS_AS(body.step(), femcourse::StepDiverged);
  REQUIRE(all_finite(positions_of(body)));
  const femcourse::DeformationStatus status = body.check_deformation();
  CHECK_FALSE(std::isnan(status.largest_stretch));
  CHECK(status.plausible == (status.largest_stretch < 5.0 && status.inverted_elements == 0));
  CHECK(all_finite(body.elastic_forces()));
  for (const NodeForce& r : body.reactions()) CHECK(all_finite({r.force.begin(), r.force.end()}));
  body.restore_state(body.save_state());  // a finite state saved after the failure restores
  body.restore_state(good);
  body.set_forces({});
  for (int k = 0; k < 3; ++k) body.step();
  CHECK(positions_of(body) == plain_run(beam(), 3));
}

TEST_CASE("call orders: every call on a moved-from body throws logic_error", "[library]") {
  Body body(beam());
  Body other(std::move(body));
  const femcourse::BodyState state = other.save_state();
  CHECK_THROWS_AS(body.reactions(), std::logic_error);
  CHECK_THROWS_AS(body.elastic_forces(), std::logic_error);
  CHECK_THROWS_AS(body.check_deformation(), std::logic_error);
  CHECK_THROWS_AS(body.save_state(), std::logic_error);
  CHECK_THROWS_AS(body.restore_state(state), std::logic_error);
  CHECK_THROWS_AS(body.set_floor({0.0, 0.0, 0.0}, {0.0, 0.0, 1.0}, 0.3), std::logic_error);
  CHECK_THROWS_AS(body.remove_floor(), std::logic_error);
  CHECK_THROWS_AS(body.grab({0}), std::logic_error);
  CHECK_THROWS_AS(body.release(), std::logic_error);
  CHECK_THROWS_AS(body.move_grabbed({0.0, 0.0, 1.0}), std::logic_error);
  CHECK_THROWS_AS(body.set_chapter("14"), std::logic_error);
  CHECK_THROWS_AS(body.set_threads(1), std::logic_error);
  CHECK_THROWS_AS(body.set_forces({}), std::logic_error);
  CHECK_THROWS_AS(body.surface(), std::logic_error);
  CHECK_THROWS_AS(body.floor_contacts(), std::logic_error);
  CHECK_THROWS_AS(body.take_warnings(), std::logic_error);
  CHECK_THROWS_AS(body.threads_used(), std::logic_error);
  CHECK_THROWS_AS(body.chapter(), std::logic_error);
  CHECK_THROWS_AS(body.time(), std::logic_error);
  CHECK_THROWS_AS(body.changes_constraints_in_place(), std::logic_error);
  other.step();  // the body moved into steps on
  CHECK(all_finite(positions_of(other)));
}

TEST_CASE("call orders: the floor's friction survives a chapter switch and a save", "[library]") {
  BodyDescription d = beam();
  d.constraints.clear();
  d.damping_alpha = 2.0;
  d.gravity = {-3.0, 0.0, -9.81};  // a pull along the floor friction 0.8 holds
  Body body(d);
  double lowest = 1e300;
  for (int i = 0; i < body.num_nodes(); ++i) lowest = std::min(lowest, body.position(i)[2]);
  body.set_floor({0.0, 0.0, lowest - 0.01}, {0.0, 0.0, 1.0}, 0.8);
  for (int k = 0; k < 40; ++k) body.step();
  REQUIRE_FALSE(body.save_state().floor_stuck.empty());
  body.set_chapter("01");
  const femcourse::BodyState after = body.save_state();
  CHECK(after.floor);
  CHECK(after.floor_friction == 0.8);
  CHECK_FALSE(after.floor_stuck.empty());
  const double x = body.position(0)[0];
  for (int k = 0; k < 20; ++k) body.step();
  CHECK(std::abs(body.position(0)[0] - x) < 1e-3);             // still held: friction kept
  body.set_floor({0.0, 0.0, lowest - 0.01}, {0.0, 0.0, 1.0});  // again, frictionless
  CHECK(body.save_state().floor_friction == 0.0);
  body.remove_floor();
  const femcourse::BodyState none = body.save_state();
  CHECK_FALSE(none.floor);
  CHECK(none.floor_contacts.empty());
  CHECK(none.floor_stuck.empty());
}

TEST_CASE("call orders: a floor contact grabbed, saved and restored at once", "[library]") {
  double floor = 0.0;
  Body body = landed_beam(0.8, floor);
  REQUIRE_FALSE(body.floor_contacts().empty());
  const int contact = body.floor_contacts().front();
  body.grab({contact}, {0.0, 0.0, 0.5});
  const femcourse::BodyState saved = body.save_state();
  CHECK(std::find(saved.floor_contacts.begin(), saved.floor_contacts.end(), contact) ==
        saved.floor_contacts.end());
  CHECK(std::find(saved.floor_stuck.begin(), saved.floor_stuck.end(), contact) ==
        saved.floor_stuck.end());
  CHECK_NOTHROW(body.restore_state(saved));  // what the body saved it takes back
  body.step();
  CHECK(body.position(contact)[2] > floor);
  body.release();
  for (int k = 0; k < 5; ++k) body.step();
  CHECK(all_finite(positions_of(body)));
}

TEST_CASE("call orders: a body's own fixed node grabbed, put on a floor, released", "[library]") {
  Body body(beam());
  const int fixed = beam().constraints.front().node;
  const std::array<double, 3> rest = body.position(fixed);
  body.grab({fixed}, {0.0, 0.0, -1.0});
  body.set_floor({0.0, 0.0, rest[2] - 0.02}, {0.0, 0.0, 1.0});
  for (int k = 0; k < 4; ++k) body.step();
  body.release();
  const std::array<double, 3> held = body.position(fixed);
  for (int k = 0; k < 4; ++k) body.step();
  CHECK(body.position(fixed) == held);  // its own constraint back: it stays where it was let go
  const std::vector<int>& contacts = body.floor_contacts();
  CHECK(std::find(contacts.begin(), contacts.end(), fixed) == contacts.end());
}

TEST_CASE("call orders: a thread count, then a single-threaded chapter, then back", "[library]") {
  Body body(beam());
  body.set_threads(2);
  body.set_chapter("01");
  body.step();
  CHECK(body.threads_used() == 1);
  CHECK(body.threads() == 2);
  body.set_chapter("");
  body.step();
  CHECK(body.threads_used() == 2);
}

TEST_CASE("call orders: a state with a floor restored, then the floor removed", "[library]") {
  double floor = 0.0;
  Body body = landed_beam(0.3, floor);
  const femcourse::BodyState saved = body.save_state();
  REQUIRE_FALSE(saved.floor_contacts.empty());
  BodyDescription d = beam();
  d.constraints.clear();
  Body other(d);  // never had a floor
  other.restore_state(saved);
  CHECK(other.floor_contacts() == saved.floor_contacts);
  other.remove_floor();
  CHECK(other.floor_contacts().empty());
  const double z = other.position(saved.floor_contacts.front())[2];
  for (int k = 0; k < 10; ++k) other.step();
  CHECK(other.position(saved.floor_contacts.front())[2] < z - 0.01);  // falls through: no floor
}

TEST_CASE("call orders: a chapter switch and a thread count between save and restore",
          "[library]") {
  Body body(beam());
  for (int k = 0; k < 4; ++k) body.step();
  const femcourse::BodyState saved = body.save_state();
  for (int k = 0; k < 4; ++k) body.step();
  const std::vector<double> after = positions_of(body);
  body.set_chapter("01");
  for (int k = 0; k < 2; ++k) body.step();
  body.set_chapter("");
  body.set_threads(2);
  body.restore_state(saved);  // the saved state alone decides every step, on any thread count
  for (int k = 0; k < 4; ++k) body.step();
  CHECK(positions_of(body) == after);
  CHECK(body.time() == Approx(0.08));
}

TEST_CASE("call orders: take_warnings twice, the second empty", "[library]") {
  BodyDescription d = beam();
  d.solver_max_iterations = 1;  // a capped solve: a warning
  Body body(d);
  body.step();
  const std::vector<std::string> first = body.take_warnings();
  CHECK_FALSE(first.empty());
  CHECK(body.take_warnings().empty());
}
