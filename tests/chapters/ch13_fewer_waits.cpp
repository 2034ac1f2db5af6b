// Chapter 13: the fused V-cycle is chapter 12's cycle in fewer loops, not another
// preconditioner (its output equals chapter 12's to the bit, on 1, 2 and 3 threads, on
// hierarchies whose level below takes each path of the fusion); the single-reduction PCG
// solves the same systems to the same tolerance in about as many iterations, reaches a tight
// one, and gives the same state on 1, 2 and 3 threads, also over a long run under a jumping
// mouse spring; the stepper matches chapter 01 and allocates nothing per step (generic tests).
#include <memory>
#include <random>
#include <sstream>

#include "catch2_compat.hpp"
#include "chapters/09_threads/parallel.hpp"
#include "chapters/12_half_the_bytes/stepper.hpp"
#include "chapters/13_fewer_waits/lesson.hpp"
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
  ch12::HalfBytesStepper stepper(scene, {}, ch10::multigrid_params<ch12::HalfTheBytes>(multigrid));
  State state = rest_state(scene);
  for (int k = 0; k < 3; ++k) stepper.step(state);
  auto& reduced = stepper.preconditioner().v_cycle();
  ch13::FusedVCycle fused(reduced, stepper.preconditioner().multigrid());
  const ThreadCountScope scope(threads);
  const Eigen::Index n = stepper.system_rhs().size();
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  double worst = 0.0;
  for (int trial = 0; trial < 3; ++trial) {
    Eigen::VectorXd r(n), s12(n), s13(n);
    for (Eigen::Index k = 0; k < n; ++k) r[k] = uniform(rng);
    ch09::run_parallel([&] {
      fused.prepare(stepper.system_matrix());
      reduced.apply(r, s12);
      fused.apply(r, s13);
    });
    worst = std::max(worst, (s12 - s13).cwiseAbs().maxCoeff());
    if (!s13.allFinite()) worst = INFINITY;
  }
  return worst;
}

State run_13(const Scene& scene, int threads, int steps, const ch10::MultigridStepperSettings& mg,
             const SolverSettings& settings = {}) {
  const ThreadCountScope scope(threads);
  ch13::FewerWaitsStepper stepper(scene, settings, ch10::multigrid_params<ch13::FewerWaits>(mg));
  stepper.team().adaptive_team().set_enabled(false);  // really this many threads, every step
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
    ch12::HalfBytesStepper probe(scene, {},
                                 ch10::multigrid_params<ch12::HalfTheBytes>(three_levels(serial)));
    REQUIRE(probe.preconditioner().multigrid().levels() == 3);
    const auto& middle = probe.preconditioner().multigrid().coarse_levels()[0];
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

namespace {

// The barriers the team meets while f() runs (chapter 09's counter: thread 0 counts each).
template <class F>
long long barriers_during(F&& f) {
  const long long before = ch09::sync_counts().barriers.load();
  f();
  return ch09::sync_counts().barriers.load() - before;
}

// The barriers of the first step of a stepper that stops after `iterations` PCG iterations
// (no tolerance reached), as the counter saw them, and as its solve phase counted them
// (StepProfile: the step's own count is the counter's). make(settings) builds one.
struct StepWaits {
  long long step = 0, solve = 0;
};
template <class Make>
StepWaits waits_of_step(const Scene& scene, Make&& make, int iterations) {
  SolverSettings settings;
  settings.tolerance = 1e-14;
  settings.max_iterations = iterations;
  const auto stepper = make(settings);
  stepper->team().adaptive_team().set_enabled(false);
  State state = rest_state(scene);
  const long long seen = barriers_during([&] { stepper->step(state); });
  REQUIRE(stepper->profile().cg_iterations == iterations);
  CHECK(stepper->profile().step.barriers == seen);
  return {seen, stepper->profile().solve.barriers};
}

// The barriers of one step per PCG iteration: steps that stop after 3 iterations and after 4,
// subtracted.
template <class Make>
long long waits_per_iteration(const Scene& scene, Make&& make) {
  return waits_of_step(scene, make, 4).step - waits_of_step(scene, make, 3).step;
}

}  // namespace

TEST_CASE("ch13: the waits counted, per V-cycle and per PCG iteration, against chapter 12's",
          "[ch13]") {
  // theory.md, section 12: a level with s smoothing steps per side costs chapter 12 2s + 3
  // waits, the coarsest one, the conversions two; the fused cycle saves the conversions, the
  // first step of each shared level below the finest and the restriction to the coarsest
  // level (it joins the coarsest solve); the PCG adds four waits per iteration (chapter 09) or one
  // (the single-reduction PCG, whose update loop also runs the cycle's entry).
  const Scene scene = test::test_scene("cantilever");
  const ThreadCountScope scope(openmp_enabled() ? 2 : 1);
  // Three levels, the finest and the middle one shared by the team: every path of the fusion.
  const ch10::MultigridStepperSettings mg = three_levels(false);
  ch12::HalfBytesStepper stepper(scene, {}, ch10::multigrid_params<ch12::HalfTheBytes>(mg));
  State state = rest_state(scene);
  stepper.step(state);
  REQUIRE(stepper.preconditioner().multigrid().levels() == 3);
  REQUIRE(!stepper.preconditioner().multigrid().fine_level().rows.serial);
  REQUIRE(!stepper.preconditioner().multigrid().coarse_levels()[0].rows.serial);
  auto& reduced = stepper.preconditioner().v_cycle();
  ch13::FusedVCycle fused(reduced, stepper.preconditioner().multigrid());
  const Eigen::VectorXd r = Eigen::VectorXd::Ones(stepper.system_rhs().size());
  Eigen::VectorXd s(r.size());
  ch09::run_parallel([&] { fused.prepare(stepper.system_matrix()); });
  const long long twelve =
      barriers_during([&] { ch09::run_parallel([&] { reduced.apply(r, s); }); });
  const long long thirteen =
      barriers_during([&] { ch09::run_parallel([&] { fused.apply(r, s); }); });
  const int steps = ch10::smoothing_steps(reduced.fine_level());
  REQUIRE(steps == 3);  // chapter 10's default: Chebyshev of degree 3, one sweep
  INFO("per V-cycle: chapter 12 " << twelve << " waits, chapter 13 " << thirteen);
  CHECK(twelve == 2 * (2 * steps + 3) + 1 + 2);  // 21
  CHECK(thirteen == twelve - 4);                 // 17
  CHECK(waits_per_iteration(scene, [&](const SolverSettings& settings) {
          return std::make_unique<ch13::FewerWaitsStepper>(
              scene, settings, ch10::multigrid_params<ch13::FewerWaits>(mg));
        }) == thirteen + 1);  // 18
  CHECK(waits_per_iteration(scene, [&](const SolverSettings& settings) {
          return std::make_unique<ch12::HalfBytesStepper>(
              scene, settings, ch10::multigrid_params<ch12::HalfTheBytes>(mg));
        }) == twelve + 4);  // 25
}

TEST_CASE("ch13: the solve phase counts its iterations' waits: iterations x the waits of one",
          "[ch13]") {
  // What the roofline prices per phase (StepProfile's solve.barriers): the single-reduction
  // PCG's solve meets, per iteration, the fused V-cycle's 17 waits on the three-level hierarchy
  // and its own one (the test above), plus what each solve meets once, whatever its iterations
  // (the set-up, the first residual): the same for 2 to 6 iterations.
  const Scene scene = test::test_scene("cantilever");
  const ThreadCountScope scope(openmp_enabled() ? 2 : 1);
  const ch10::MultigridStepperSettings mg = three_levels(false);
  const auto make = [&](const SolverSettings& settings) {
    return std::make_unique<ch13::FewerWaitsStepper>(scene, settings,
                                                     ch10::multigrid_params<ch13::FewerWaits>(mg));
  };
  const long long per_iteration = waits_per_iteration(scene, make);
  REQUIRE(per_iteration > 0);  // 18: checked against the theory in the test above
  const long long once = waits_of_step(scene, make, 2).solve - 2 * per_iteration;
  CHECK(once >= 0);
  for (const int iterations : {3, 4, 6}) {
    INFO(iterations << " iterations");
    const StepWaits waits = waits_of_step(scene, make, iterations);
    CHECK(waits.solve == once + iterations * per_iteration);
    CHECK(waits.solve < waits.step);  // the other phases wait too
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

TEST_CASE("ch13: soak, thousands of steps under a jumping mouse spring, 1 and 2 threads",
          "[ch13][soak]") {
  test::check_soak<ch13::FewerWaitsStepper>(test::test_scene("cantilever"));
}

TEST_CASE("ch13: the iterations lesson's counts, per setting, the same on 1 and 2 threads",
          "[ch13]") {
  // fem_lessons iterations: each setting's mean PCG iterations per step and the roofline's
  // bytes per iteration. The counts are the stepper's (deterministic, on any thread count);
  // a smoother of higher degree reads more bytes per iteration and takes fewer iterations.
  const Scene scene = test::test_scene("cantilever");
  const auto cost = [&](auto change, int threads) {
    ch10::MultigridStepperSettings s;
    change(s.multigrid);
    const ThreadCountScope scope(threads);
    return ch13::iteration_cost(scene, {}, s, 5, 20);
  };
  const auto same = [](ch10::MultigridSettings&) {};
  const auto degree2 = [](ch10::MultigridSettings& s) { s.relax.chebyshev_degree = 2; };
  const auto degree4 = [](ch10::MultigridSettings& s) { s.relax.chebyshev_degree = 4; };
  const auto unsmoothed = [](ch10::MultigridSettings& s) {
    s.coarsening.smooth_prolongator = false;
  };
  const ch13::IterationCost base = cost(same, 1), two = cost(same, 2), low = cost(degree2, 1),
                            high = cost(degree4, 1), plain = cost(unsmoothed, 1);
  INFO("mean iterations: degree 3 " << base.mean_iterations << ", degree 2 " << low.mean_iterations
                                    << ", degree 4 " << high.mean_iterations << ", P = T "
                                    << plain.mean_iterations);
  CHECK(two.mean_iterations == base.mean_iterations);
  CHECK(two.bytes_per_step == base.bytes_per_step);
  // Iterations in all over the 20 counted steps.
  CHECK(20 * base.mean_iterations == Approx(68).margin(1e-9));
  CHECK(20 * low.mean_iterations == Approx(90).margin(1e-9));
  CHECK(20 * high.mean_iterations == Approx(55).margin(1e-9));
  CHECK(20 * plain.mean_iterations == Approx(81).margin(1e-9));
  CHECK(low.bytes_per_iteration < base.bytes_per_iteration);
  CHECK(base.bytes_per_iteration < high.bytes_per_iteration);
  CHECK(plain.bytes_per_iteration < base.bytes_per_iteration);
  // Per step: the iterations' bytes and, once, the finest level's conversion to float.
  CHECK(base.bytes_per_step > base.mean_iterations * base.bytes_per_iteration);
}

TEST_CASE("ch13: the printed summary names every part of the recipe and the hierarchy's levels",
          "[ch13]") {
  const Scene scene = test::test_scene("cantilever");
  const ch13::FewerWaitsStepper stepper(scene, {});
  std::ostringstream out;
  out << static_cast<const Stepper&>(stepper);
  const std::string text = out.str();
  ch13::FewerWaitsStepper::for_each_part([&](const ch08::PartName& part) {
    INFO(part.role);
    CHECK(text.find(std::string(part.role) + ": " + part.name + " (" + std::string(part.chapter) +
                    ")") != std::string::npos);
  });
  const int levels = stepper.preconditioner().multigrid().levels();
  for (int l = 0; l < levels; ++l)
    CHECK(text.find("level " + std::to_string(l) + ":") != std::string::npos);
  CHECK(text.find("(13_fewer_waits)") != std::string::npos);
  CHECK(text.find("(11_node_order)") != std::string::npos);
}
