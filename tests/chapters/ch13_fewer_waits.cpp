// Chapter 13: the fused V-cycle is chapter 12's cycle in fewer loops, not another
// preconditioner (its output equals chapter 12's to the bit, on 1, 2 and 3 threads, on
// hierarchies whose level below takes each path of the fusion); the single-reduction PCG
// solves the same systems to the same tolerance in about as many iterations, reaches a tight
// one, and gives the same state on 1, 2 and 3 threads, also over a long run under a jumping
// mouse spring; the stepper matches chapter 01 and allocates nothing per step (generic tests).
#include <random>

#include "catch2_compat.hpp"
#include "chapters/09_threads/parallel.hpp"
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

// The preconditioned residuals s = M r of chapter 12's float V-cycle and of the fused one, on
// the system of a few steps of chapter 12, for filtered random r: the largest difference, on
// `threads` threads, both applied inside one team as the PCG applies them.
double fused_against_chapter_12(const Scene& scene, int threads,
                                const ch10::MultigridStepperSettings& multigrid) {
  ch12::HalfBytesStepper stepper(scene, {}, ch12::Arithmetic::single, multigrid);
  State state = rest_state(scene);
  for (int k = 0; k < 3; ++k) stepper.step(state);
  auto& reduced = dynamic_cast<ch12::ReducedVCycle<float>&>(stepper.v_cycle());
  ch13::FusedVCycle fused(reduced, stepper.multigrid());
  const ThreadCountScope scope(threads);
  const Eigen::Index n = stepper.system_rhs().size();
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  double worst = 0.0;
  for (int trial = 0; trial < 3; ++trial) {
    Eigen::VectorXd r(n), s12(n), s13(n);
    for (Eigen::Index k = 0; k < n; ++k) r[k] = uniform(rng);
    ch09::run_parallel([&] {
      fused.prepare(stepper.system_matrix(), ch09::RowChunks{});
      reduced.apply(ch09::RowChunks{}, r, s12);
      fused.apply(ch09::RowChunks{}, r, s13);
    });
    worst = std::max(worst, (s12 - s13).cwiseAbs().maxCoeff());
    if (!s13.allFinite()) worst = INFINITY;
  }
  return worst;
}

State run_13(const Scene& scene, int threads, int steps, const ch10::MultigridStepperSettings& mg,
             const SolverSettings& settings = {}) {
  const ThreadCountScope scope(threads);
  ch13::FewerWaitsStepper stepper(scene, settings, mg);
  stepper.adaptive_team().set_enabled(false);  // really this many threads, every step
  State state = rest_state(scene);
  for (int k = 0; k < steps; ++k) {
    stepper.step(state);
    REQUIRE(stepper.profile().converged);
  }
  return state;
}

}  // namespace

TEST_CASE("ch13: the fused V-cycle is chapter 12's to the bit, on every path and thread count",
          "[ch13]") {
  const Scene scene = test::test_scene("cantilever");
  for (const bool serial : {false, true}) {
    // The hierarchy really has a middle level (shared, or serial) above the coarsest.
    ch12::HalfBytesStepper probe(scene, {}, ch12::Arithmetic::single, three_levels(serial));
    REQUIRE(probe.multigrid().levels() == 3);
    const auto& middle = probe.multigrid().coarse_levels()[0];
    REQUIRE(middle.rows.serial == serial);
    REQUIRE((serial || middle.rows.count() > 1));
    for (const int threads : thread_counts()) {
      INFO((serial ? "serial" : "shared") << " middle level on " << threads << " threads");
      CHECK(fused_against_chapter_12(scene, threads, three_levels(serial)) == 0.0);
    }
  }
  for (const Scene& s : test::equivalence_scenes())
    for (const int threads : thread_counts()) {
      INFO(s.name << ", default hierarchy, on " << threads << " threads");
      CHECK(fused_against_chapter_12(s, threads, {}) == 0.0);
    }
}

TEST_CASE("ch13: about chapter 12's iterations at 1e-4, and 1e-10 still reached", "[ch13]") {
  // Chronopoulos and Gear's CG: in exact arithmetic chapter 09's iterates; in rounding, close.
  for (const double tolerance : {1e-4, 1e-10}) {
    for (const Scene& scene : test::equivalence_scenes()) {
      SolverSettings settings;
      settings.tolerance = tolerance;
      ch12::HalfBytesStepper twelve(scene, settings);
      ch13::FewerWaitsStepper thirteen(scene, settings);
      State a = rest_state(scene), b = a;
      int worst = 0, total12 = 0, total13 = 0;
      for (int k = 0; k < 20; ++k) {
        twelve.step(a);
        thirteen.step(b);
        REQUIRE(thirteen.profile().converged);
        total12 += twelve.profile().cg_iterations;
        total13 += thirteen.profile().cg_iterations;
        worst = std::max(worst, thirteen.profile().cg_iterations - twelve.profile().cg_iterations);
      }
      INFO(scene.name << ", tolerance " << tolerance << ": most extra iterations " << worst
                      << ", in all " << total13 << " against " << total12);
      CHECK(worst <= 1);
      CHECK((b.x - a.x).cwiseAbs().maxCoeff() < 1e3 * tolerance);
    }
  }
}

TEST_CASE("ch13: the same state on 1, 2 and 3 threads with a shared and a serial middle level",
          "[ch13]") {
  const Scene scene = test::driven_scene();
  for (const bool serial : {false, true}) {
    const State first = run_13(scene, 1, 20, three_levels(serial));
    for (const int threads : thread_counts()) {
      const State state = run_13(scene, threads, 20, three_levels(serial));
      INFO((serial ? "serial" : "shared") << " middle level on " << threads << " threads");
      CHECK(bit_identical(state.x, first.x));
      CHECK(bit_identical(state.v, first.v));
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

namespace {

struct Soak {
  State state;
  int not_converged = 0;
  std::string diverged;
  double max_speed_early = 0.0, max_speed = 0.0;
};

// A long run under the jumping mouse spring (support.hpp), a new node every 7 steps.
Soak soak(const Scene& scene, int threads, int steps) {
  const ThreadCountScope scope(threads);
  ch13::FewerWaitsStepper stepper(scene, {});
  stepper.adaptive_team().set_enabled(false);
  test::JumpingMouse mouse(scene, 7);
  Soak out;
  out.state = rest_state(scene);
  for (int k = 0; k < steps; ++k) {
    stepper.set_external_forces(mouse.force(k, out.state));
    stepper.step(out.state);
    if (const char* why = divergence(out.state, stepper.profile())) {
      out.diverged = why;
      return out;
    }
    out.not_converged += stepper.profile().converged ? 0 : 1;
    out.max_speed = std::max(out.max_speed, out.state.v.cwiseAbs().maxCoeff());
    if (k < 300) out.max_speed_early = out.max_speed;
  }
  return out;
}

}  // namespace

TEST_CASE("ch13: soak, thousands of steps under a jumping mouse spring, 1 and 2 threads",
          "[ch13][soak]") {
  // Every solve converges, no step diverges, the motion stays bounded (damping takes out what
  // the spring puts in), and the two thread counts give the same bits.
  const Scene scene = test::test_scene("cantilever");
  const int steps = test::soak_steps(2000);
  const Soak one = soak(scene, 1, steps);
  const Soak two = soak(scene, openmp_enabled() ? 2 : 1, steps);
  for (const Soak* run : {&one, &two}) {
    CHECK(run->diverged.empty());
    CHECK(run->not_converged == 0);
    CHECK(run->max_speed_early > 0.0);
    CHECK(run->max_speed < 10.0 * run->max_speed_early);
  }
  CHECK(bit_identical(one.state.x, two.state.x));
  CHECK(bit_identical(one.state.v, two.state.v));
}
