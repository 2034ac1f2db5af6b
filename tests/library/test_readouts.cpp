// The read-outs are by-products of the elements' forces (femcourse/node_forces.hpp): equal to
// common/'s force pass, free of allocations on every new state, never changing a later step,
// and the floor under a body that lands flat (half its nodes held at once) leaves every solve
// converged.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "common/alloc_counter.hpp"
#include "common/model.hpp"
#include "common/scene.hpp"
#include "femcourse/simulator.hpp"
#include "support.hpp"
#include "test_beam.hpp"

namespace {

using femcourse::Body;
using femcourse::BodyDescription;

BodyDescription free_beam() {
  BodyDescription d = fem::test::clamped_beam_description();
  d.constraints.clear();
  return d;
}

// The beam resting on a floor with friction, one node dragged back and forth over it.
void dragged_on_floor(Body& body, int steps, bool read) {
  for (int k = 0; k < steps; ++k) {
    if (k == 60) body.grab({body.num_nodes() - 1});
    if (k >= 60) body.move_grabbed({0.3 * std::sin(0.1 * k), 0.0, 0.05 * std::cos(0.1 * k)});
    body.step();
    if (read) {
      body.reactions();
      body.elastic_forces();
    }
  }
}

}  // namespace

TEST_CASE("the read-outs equal common/'s force pass, with and without the floor", "[library]") {
  for (const bool floor : {false, true}) {
    INFO((floor ? "resting on a floor" : "clamped"));
    Body body(floor ? free_beam() : fem::test::clamped_beam_description());
    if (floor) body.set_floor({0.0, 0.0, -0.05}, {0.0, 0.0, 1.0}, 0.5);
    for (int k = 0; k < 80; ++k) body.step();
    const fem::Model model(body.scene());
    std::vector<Eigen::Matrix3d> rotations(model.tets.size());
    Eigen::VectorXd f(model.dofs);
    fem::compute_rotations_and_forces(model, body.state().x, rotations, f);
    const Eigen::VectorXd elastic = f - model.gravity_force;
    const std::vector<double>& read = body.elastic_forces();
    REQUIRE(read.size() == static_cast<std::size_t>(model.dofs));
    const double scale = elastic.cwiseAbs().maxCoeff();
    REQUIRE(scale > 0.0);
    double worst = 0.0;
    for (Eigen::Index i = 0; i < model.dofs; ++i)
      worst = std::max(worst, std::abs(read[static_cast<std::size_t>(i)] - elastic[i]));
    INFO("largest difference " << worst << " N, largest force " << scale << " N");
    CHECK(worst <= 1e-9 * scale);
  }
}

TEST_CASE("reactions and elastic_forces allocate nothing on each new state once sized",
          "[library]") {
  REQUIRE(fem::alloc::enabled());
  Body body(fem::test::clamped_beam_description());
  for (int k = 0; k < 5; ++k) {
    body.step();
    body.reactions();
    body.elastic_forces();
  }
  long long allocations = 0;
  double held = 0.0;
  for (int k = 0; k < 10; ++k) {
    body.step();  // its own allocations are the stepper's (none: tests/chapters)
    const fem::alloc::Scope scope;
    for (const auto& r : body.reactions()) held += r.force[2];
    held += body.elastic_forces().front();
    allocations += scope.allocations();
  }
  CHECK(allocations == 0);
  CHECK(std::isfinite(held));
}

TEST_CASE("reading the forces after every step changes no later step, to the bit", "[library]") {
  // The floor decides (release, friction) by the elements' forces; a read-out that moved
  // Newton's starts would change their last bits, and the floor's decisions with them.
  Body reading(free_beam()), not_reading(free_beam());
  for (Body* body : {&reading, &not_reading})
    body->set_floor({0.0, 0.0, -0.05}, {0.0, 0.0, 1.0}, 0.3);
  dragged_on_floor(reading, 160, true);
  dragged_on_floor(not_reading, 160, false);
  const int values = 3 * reading.num_nodes();
  CHECK(std::equal(reading.positions(), reading.positions() + values, not_reading.positions()));
  CHECK(std::equal(reading.velocities(), reading.velocities() + values, not_reading.velocities()));
  CHECK(reading.floor_contacts() == not_reading.floor_contacts());
}

TEST_CASE("a plate landing flat on a floor, half its nodes at once, converges in every step",
          "[library]") {
  // 964 of the plate's 2069 nodes land in one step: the default chapter's multigrid sets its
  // coarse space up again for them (before, chapters 12-14 stopped at the iteration cap).
  BodyDescription d;
  d.time_step = 0.01;
  Body body = femcourse::body_from_gmsh_file(fem::test::mesh_path("plate_poster.msh"), d);
  double lowest = 1e300;
  for (int i = 0; i < body.num_nodes(); ++i) lowest = std::min(lowest, body.position(i)[2]);
  body.set_floor({0.0, 0.0, lowest}, {0.0, 0.0, 1.0});
  int most = 0;
  for (int k = 0; k < 30; ++k) {
    REQUIRE_NOTHROW(body.step());
    CHECK(body.profile().converged);
    most = std::max(most, body.profile().iterations);
  }
  INFO("at most " << most << " CG iterations a step");
  CHECK(body.floor_contacts().size() == 964);
  CHECK(most <= 40);
}

TEST_CASE("a body refuses an OMP_NUM_THREADS that is not a count, before any OpenMP call",
          "[library]") {
  // LLVM's libomp aborts the process on these at its first call; the body must refuse first.
  const char* kept = std::getenv("OMP_NUM_THREADS");
  const std::string before = kept ? kept : "";
  for (const char* value : {"1.5", "", "+2", "two"}) {
    INFO("OMP_NUM_THREADS='" << value << "'");
    ::setenv("OMP_NUM_THREADS", value, 1);
    CHECK_THROWS_WITH(Body(fem::test::clamped_beam_description()),
                      fem::test::contains_text("is not a thread count"));
  }
  ::setenv("OMP_NUM_THREADS", "1", 1);
  CHECK_NOTHROW(Body(fem::test::clamped_beam_description()));
  if (kept)
    ::setenv("OMP_NUM_THREADS", before.c_str(), 1);
  else
    ::unsetenv("OMP_NUM_THREADS");
}
