// Chapter 13: the fused V-cycle is chapter 12's cycle in fewer loops, not another
// preconditioner: the stepper's state equals chapter 12's to the bit on every scene, on 1, 2
// and 3 threads, on hierarchies whose levels below take each path of the fusion (a shared
// level, a small one on one thread, the coarsest), and over a long run under a jumping mouse
// spring; it matches chapter 01 and allocates nothing per step (the generic tests too).
#include "catch2_compat.hpp"
#include "chapters/12_half_the_bytes/stepper.hpp"
#include "chapters/13_fewer_waits/stepper.hpp"
#include "common/threads.hpp"
#include "support.hpp"

using namespace fem;

FEM_CHAPTER_TESTS("13", "[ch13]")

namespace {

// 1, 2 and 3 threads with OpenMP (3: a count that divides nothing evenly); 1 without.
std::vector<int> thread_counts() {
  return openmp_enabled() ? std::vector<int>{1, 2, 3} : std::vector<int>{1};
}

bool bit_identical(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return a.size() == b.size() && (a.array() == b.array()).all();
}

// Three levels on the test mesh with small row blocks, so that the middle level is shared
// by the team; with `serial`, the middle level runs on one thread (chapter 10's serial_rows).
ch10::MultigridStepperSettings three_levels(bool serial) {
  ch10::MultigridStepperSettings s;
  s.multigrid.max_coarse_dofs = 24;
  s.multigrid.rows.block_rows = 4;
  if (serial) s.multigrid.rows.serial_rows = 1000;  // every coarse level: one thread
  return s;
}

// Chapters 12 and 13 side by side, `steps` steps (with the mouse spring when given a hold):
// the number of steps whose states differ in any bit, and chapter 13's final state.
struct SideBySide {
  int differing_steps = 0, not_converged = 0;
  State state;
};
SideBySide side_by_side(const Scene& scene, int threads, int steps,
                        const ch10::MultigridStepperSettings& multigrid, int hold = 0) {
  const ThreadCountScope scope(threads);
  ch12::HalfBytesStepper twelve(scene, {}, ch12::Arithmetic::single, multigrid);
  ch13::FewerWaitsStepper thirteen(scene, {}, multigrid);
  twelve.adaptive_team().set_enabled(false);  // really this many threads, every step
  thirteen.adaptive_team().set_enabled(false);
  test::JumpingMouse mouse(scene, std::max(hold, 1));
  SideBySide out;
  State a = rest_state(scene);
  out.state = a;
  for (int k = 0; k < steps; ++k) {
    if (hold > 0) {
      const auto forces = mouse.force(k, a);
      twelve.set_external_forces(forces);
      thirteen.set_external_forces(forces);
    }
    twelve.step(a);
    thirteen.step(out.state);
    if (!bit_identical(a.x, out.state.x) || !bit_identical(a.v, out.state.v)) ++out.differing_steps;
    out.not_converged += thirteen.profile().converged ? 0 : 1;
  }
  return out;
}

}  // namespace

TEST_CASE("ch13: chapter 12's state to the bit on every scene, on 1, 2 and 3 threads", "[ch13]") {
  for (const Scene& scene : test::equivalence_scenes()) {
    State first;
    for (const int threads : thread_counts()) {
      const SideBySide run = side_by_side(scene, threads, 30, {});
      INFO(scene.name << " on " << threads << " threads");
      CHECK(run.differing_steps == 0);
      CHECK(run.not_converged == 0);
      if (threads == 1) first = run.state;
      CHECK(bit_identical(run.state.x, first.x));
      CHECK(bit_identical(run.state.v, first.v));
    }
  }
}

TEST_CASE("ch13: the same bits when the level below is shared, on one thread, or the coarsest",
          "[ch13]") {
  for (const bool serial : {false, true}) {
    const Scene scene = test::test_scene("cantilever");
    {
      // The hierarchy really has a middle level (shared, or serial) above the coarsest.
      ch13::FewerWaitsStepper probe(scene, {}, three_levels(serial));
      REQUIRE(probe.multigrid().levels() == 3);
      const auto& middle = probe.multigrid().coarse_levels()[0];
      REQUIRE(middle.rows.serial == serial);
      REQUIRE((serial || middle.rows.count() > 1));
    }
    for (const int threads : thread_counts()) {
      const SideBySide run = side_by_side(scene, threads, 20, three_levels(serial));
      INFO((serial ? "serial" : "shared") << " middle level on " << threads << " threads");
      CHECK(run.differing_steps == 0);
      CHECK(run.not_converged == 0);
    }
  }
}

TEST_CASE("ch13: zero heap allocations per step after the first, with 2 threads", "[ch13]") {
  FEM_REQUIRE_ALLOCATION_COUNTER();
  const ThreadCountScope two(openmp_enabled() ? 2 : 1);
  for (const Scene& scene : test::equivalence_scenes()) {
    INFO(scene.name);
    CHECK(test::allocations_per_step("13", scene) == 0);
  }
}

TEST_CASE("ch13: soak, thousands of steps under a jumping mouse spring, chapter 12's bits",
          "[ch13][soak]") {
  // Every solve converges, no step diverges, and every step equals chapter 12's on 2 threads.
  const Scene scene = test::test_scene("cantilever");
  const int steps = test::soak_steps(2000);
  const SideBySide run = side_by_side(scene, openmp_enabled() ? 2 : 1, steps, {}, 7);
  CHECK(run.differing_steps == 0);
  CHECK(run.not_converged == 0);
  CHECK(run.state.x.allFinite());
  CHECK(run.state.v.allFinite());
}
