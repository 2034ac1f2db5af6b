// The library's state is whole (issue 65): the read-outs in any order, a saved state that holds
// its floor, restore_state refusing what does not fit (in the caller's node numbers), and the
// thread count asked for being the one that steps, as the stepper's team recorded it.
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "chapters/09_threads/adaptive_team.hpp"
#include "common/alloc_counter.hpp"
#include "common/threads.hpp"
#include "femcourse/simulator.hpp"
#include "support.hpp"
#include "test_beam.hpp"

namespace {

using femcourse::Body;
using femcourse::BodyDescription;
using femcourse::BodyState;

// The test beam (nodes at min x fixed, gravity -z) as arrays.
BodyDescription clamped_beam() { return fem::test::clamped_beam_description(); }

// The same beam with nothing holding it: it falls onto a floor.
BodyDescription free_beam() {
  BodyDescription d = clamped_beam();
  d.constraints.clear();
  return d;
}

std::vector<double> positions_of(const Body& body) {
  return {body.positions(), body.positions() + 3 * body.num_nodes()};
}

double lowest_z(const Body& body) {
  double z = 1e300;
  for (int i = 0; i < body.num_nodes(); ++i) z = std::min(z, body.position(i)[2]);
  return z;
}

// Steps until the body rests on the floor with contacts (at most 200 steps).
void land(Body& body) {
  for (int k = 0; k < 200 && body.floor_contacts().empty(); ++k) body.step();
  REQUIRE_FALSE(body.floor_contacts().empty());
}

void refused_with(Body& body, const BodyState& state, const std::string& words) {
  const std::vector<double> before = positions_of(body);
  try {
    body.restore_state(state);
    FAIL("restore_state accepted a state it should refuse (" << words << ")");
  } catch (const std::invalid_argument& e) {
    CHECK_THAT(e.what(), fem::test::contains_text(words));
  }
  CHECK(positions_of(body) == before);
}

}  // namespace

TEST_CASE("elastic_forces is the first call on a fresh body without crashing", "[library]") {
  const Body fresh(clamped_beam());
  const std::vector<double> first = fresh.elastic_forces();  // before any reactions()
  REQUIRE(first.size() == static_cast<std::size_t>(3 * fresh.num_nodes()));
  double largest = 0.0;
  for (const double f : first) largest = std::max(largest, std::abs(f));
  CHECK(largest < 1e-9);  // at rest: no strain, up to rounding
  Body body(clamped_beam());
  body.step();
  const std::vector<double> elastic = body.elastic_forces();
  const auto reactions = body.reactions();
  CHECK(body.elastic_forces() == elastic);  // in any order, the same read-outs
  CHECK(body.reactions().size() == reactions.size());
  CHECK(body.floor_contacts().empty());
}

TEST_CASE("a saved state holds its floor: removing the floor after saving changes nothing",
          "[library]") {
  Body body(free_beam()), twin(free_beam());
  for (Body* b : {&body, &twin}) b->set_floor({0.0, 0.0, -0.05}, {0.0, 0.0, 1.0});
  land(body);
  land(twin);
  const BodyState saved = body.save_state();
  twin.save_state();  // saving restarts the stepper: the twin does as the body does
  CHECK(saved.floor);
  CHECK(saved.floor_point[2] == -0.05);
  body.remove_floor();
  body.step();
  body.restore_state(saved);  // the floor comes back with its contacts
  CHECK(body.floor_contacts() == twin.floor_contacts());
  for (int k = 0; k < 30; ++k) {
    body.step();
    twin.step();
  }
  CHECK(positions_of(body) == positions_of(twin));
  CHECK(lowest_z(body) >= -0.05 - 1e-12);
}

TEST_CASE(
    "a state without a floor removes the body's floor, and one with contacts but no floor "
    "is refused",
    "[library]") {
  Body body(free_beam());
  const BodyState floorless = body.save_state();  // no floor, no contacts
  body.set_floor({0.0, 0.0, -0.05}, {0.0, 0.0, 1.0});
  land(body);
  body.restore_state(floorless);
  CHECK(body.floor_contacts().empty());
  for (int k = 0; k < 100; ++k) body.step();
  CHECK(lowest_z(body) < -0.2);  // nothing holds it: it falls through where the floor was

  Body fresh(free_beam());
  BodyState contacts_without_floor = fresh.save_state();
  contacts_without_floor.floor_contacts = {6};
  refused_with(fresh, contacts_without_floor, "1 floor contacts but no floor");
  CHECK(fresh.floor_contacts().empty());
}

TEST_CASE(
    "restore_state refuses a NaN, a short array and contacts on held nodes, by the "
    "caller's node numbers",
    "[library]") {
  Body body(clamped_beam());
  body.step();
  const BodyState good = body.save_state();
  BodyState nan = good;
  nan.positions[4] = std::numeric_limits<double>::quiet_NaN();
  refused_with(body, nan, "NaN or infinite position or velocity");
  BodyState infinite = good;
  infinite.velocities[0] = std::numeric_limits<double>::infinity();
  refused_with(body, infinite, "NaN or infinite");
  BodyState short_v = good;
  short_v.velocities.resize(3);
  refused_with(body, short_v, "3 velocity values");
  const std::vector<femcourse::Constraint> constraints = clamped_beam().constraints;
  const int held = constraints.front().node;
  BodyState on_held = good;
  on_held.floor = true;
  on_held.floor_contacts = {held};
  refused_with(body, on_held, "node " + std::to_string(held) + ", which has a constraint");
  int free_node = 0;
  while (std::any_of(constraints.begin(), constraints.end(),
                     [&](const auto& c) { return c.node == free_node; }))
    ++free_node;
  BodyState twice = good;
  twice.floor = true;
  twice.floor_contacts = {free_node, free_node};
  refused_with(body, twice, "node " + std::to_string(free_node) + " twice");
  BodyState bad_floor = good;
  bad_floor.floor = true;
  bad_floor.floor_normal = {0.0, 0.0, 0.0};
  refused_with(body, bad_floor, "the normal not zero");
  body.restore_state(good);  // and the good one still restores
  CHECK(positions_of(body) == good.positions);
}

TEST_CASE("a solver tolerance of 1 or more is refused: the solve would never start", "[library]") {
  for (const double tolerance : {1.0, 5.0}) {
    BodyDescription d = clamped_beam();
    d.solver_tolerance = tolerance;
    CHECK_THROWS_WITH(Body(d), fem::test::contains_text("it must lie in (0, 1)"));
  }
  BodyDescription d = clamped_beam();
  d.solver_tolerance = 0.5;
  CHECK_NOTHROW(Body(d));
}

TEST_CASE("the threads asked for are the threads a step ran on, by the team's own record",
          "[library][threads]") {
  if (!fem::openmp_enabled()) return;  // one thread is all a build without OpenMP runs
  BodyDescription d = clamped_beam();  // far below kSmallBodyNodes
  Body automatic(d);
  automatic.step();
  CHECK(automatic.threads_used() == 1);  // not asked: the library's one thread
  d.threads = 2;
  Body asked(d);
  CHECK(asked.threads_used() == 0);  // before any step
  for (int k = 0; k < 3; ++k) {
    asked.step();
    CHECK(asked.threads_used() == 2);
  }
  d.chapter = "01";
  Body serial(d);
  serial.step();
  CHECK(serial.threads_used() == 1);  // a single-threaded chapter, whatever is asked
}

TEST_CASE("an asked thread count keeps chapter 09's adaptive team from choosing one thread",
          "[library][threads]") {
  // A probe on one thread much faster than two would switch the team (adaptive_team.hpp).
  const auto teams_after_fast_probes = [] {
    fem::ch09::AdaptiveTeam team;
    int fewest = 2;
    for (int k = 0; k < 64; ++k) {
      const int n = team.next(2);
      team.record(n == 1 ? 0.001 : 0.01);
      fewest = std::min(fewest, n);
    }
    return fewest;
  };
  CHECK(teams_after_fast_probes() == 1);  // not asked: the team may take one
  const fem::AskedThreadsScope asked(true);
  CHECK(teams_after_fast_probes() == 2);
}

TEST_CASE("a floor raised under a resting body carries it up", "[library]") {
  Body body(free_beam());
  body.set_floor({0.0, 0.0, -0.05}, {0.0, 0.0, 1.0});
  land(body);
  for (int k = 0; k < 20; ++k) body.step();
  body.set_floor({0.0, 0.0, -0.03}, {0.0, 0.0, 1.0});  // 2 cm up
  for (int k = 0; k < 5; ++k) body.step();
  CHECK(lowest_z(body) >= -0.03 - 1e-12);
  CHECK_FALSE(body.floor_contacts().empty());
}

TEST_CASE("the read-outs of a body resting on the floor allocate nothing once sized", "[library]") {
  REQUIRE(fem::alloc::enabled());
  Body body(free_beam());
  body.set_floor({0.0, 0.0, -0.05}, {0.0, 0.0, 1.0});
  land(body);
  for (int k = 0; k < 20; ++k) body.step();
  const std::size_t contacts = body.reactions().size();  // sizes the storage
  body.elastic_forces();
  double up = 0.0;
  std::size_t elastic = 0, reactions = 0;
  long long allocations = 0;
  {
    const fem::alloc::Scope scope;  // no assertion inside: Catch may allocate in one
    for (int k = 0; k < 10; ++k) {
      for (const auto& r : body.reactions()) up += r.force[2];
      elastic += body.elastic_forces().size();
      reactions += body.reactions().size();  // again: the same state's, no new storage
    }
    allocations = scope.allocations();
  }
  CHECK(allocations == 0);
  CHECK(elastic == static_cast<std::size_t>(30 * body.num_nodes()));
  CHECK(reactions == 10 * contacts);
  CHECK(up > 0.0);  // the floor holds the body up
}

TEST_CASE(
    "a 2 m drop at 60 Hz lands without an inverted element in sub-steps, and warns "
    "naming them without",
    "[library]") {
  // The review's jelly block: E = 5e4, dropped 2 m onto a floor, one step() a frame.
  const auto drop = [](int substeps, std::vector<std::string>* warnings) {
    BodyDescription d = free_beam();
    d.youngs_modulus = 5e4;
    d.time_step = 1.0 / 60.0;
    d.substeps = substeps;
    Body body(d);
    body.set_floor({0.0, 0.0, lowest_z(body) - 2.0}, {0.0, 0.0, 1.0});
    int most_inverted = 0;
    for (int frame = 0; frame < 90; ++frame) {
      body.step();
      most_inverted = std::max(most_inverted, body.check_deformation().inverted_elements);
    }
    CHECK_FALSE(body.floor_contacts().empty());  // it landed
    if (warnings) *warnings = body.take_warnings();
    return most_inverted;
  };
  std::vector<std::string> warnings;
  const int one = drop(1, &warnings);
  CHECK(one > 0);
  REQUIRE(warnings.size() == 1);
  CHECK_THAT(warnings.front(), fem::test::contains_text("raise BodyDescription::substeps (now 1)"));
  CHECK(drop(8, nullptr) == 0);
  BodyDescription d = free_beam();
  d.substeps = 0;
  CHECK_THROWS_WITH(Body(d), fem::test::contains_text("substeps is 0: 1 to 1000"));
}

TEST_CASE("a drag allocates nothing per frame once sized: move_grabbed, then a step", "[library]") {
  Body body(clamped_beam());  // the default chapter changes its constraints in place
  REQUIRE(body.changes_constraints_in_place());
  std::vector<int> tip;
  for (int i = 0; i < body.num_nodes(); ++i)
    if (body.position(i)[0] > 0.99) tip.push_back(i);
  REQUIRE_FALSE(tip.empty());
  body.grab(tip, {0.0, 0.0, 0.1});
  for (int k = 0; k < 3; ++k) {  // sizes every store a frame uses
    body.move_grabbed({0.0, 0.01 * k, 0.1});
    body.step();
  }
  long long moving = 0, stepping = 0;
  for (int k = 0; k < 10; ++k) {
    {
      const fem::alloc::Scope scope;
      body.move_grabbed({0.0, 0.02 * k, -0.1});
      moving += scope.allocations();
    }
    const fem::alloc::Scope scope;
    body.step();
    stepping += scope.allocations();
  }
  CHECK(moving == 0);
  CHECK(stepping == 0);
  CHECK(body.grabbed() == tip);
  CHECK_THROWS_AS(body.move_grabbed({0.0, std::nan(""), 0.0}), std::invalid_argument);
}
