// Chapter 09: the same answer, to the last bit, for any thread count; the same physics as
// chapter 01; no allocation per step with threads; and a long run under a random mouse
// spring for every chapter from 07 on.

#include "catch2_compat.hpp"
#include "chapters/08_element_kernels/stepper.hpp"
#include "chapters/09_threads/parallel.hpp"
#include "chapters/09_threads/stepper.hpp"
#include "chapters/registry.hpp"
#include "common/model.hpp"
#include "common/threads.hpp"
#include "support.hpp"

using namespace fem;

namespace {

// 1, 2 and 3 threads with OpenMP (3: a count that divides nothing evenly); 1 without.
std::vector<int> thread_counts() {
  return openmp_enabled() ? std::vector<int>{1, 2, 3} : std::vector<int>{1};
}

State run_with(const Scene& scene, int threads, int steps, ch09::ElementParallelism how) {
  const ThreadCountScope scope(threads);
  ch09::ThreadsStepper stepper(scene, {}, ch09::parallelism(how));
  stepper.team().adaptive_team().set_enabled(false);  // really this many threads, every step
  State state = rest_state(scene);
  for (int k = 0; k < steps; ++k) stepper.step(state);
  return state;
}

bool bit_identical(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return a.size() == b.size() && (a.array() == b.array()).all();
}

}  // namespace

TEST_CASE("ch09: bit-identical states after 50 steps with 1, 2 and 3 threads", "[ch09]") {
  for (const auto how : {ch09::ElementParallelism::colouring, ch09::ElementParallelism::gather})
    for (const Scene& scene : {test::test_scene("cantilever"), test::driven_scene()}) {
      const State reference = run_with(scene, 1, 50, how);
      REQUIRE((reference.x - rest_state(scene).x).cwiseAbs().maxCoeff() > 1e-3);  // it moves
      for (const int threads : thread_counts()) {
        const State state = run_with(scene, threads, 50, how);
        INFO(scene.name << ", " << threads << " threads, "
                        << (how == ch09::ElementParallelism::gather ? "gather" : "colouring"));
        CHECK(bit_identical(state.x, reference.x));
        CHECK(bit_identical(state.v, reference.v));
      }
    }
}

// The generic chapter tests run at the process's thread count: .ci/run runs this binary
// under OMP_NUM_THREADS=1 and 2, and the states are bit-identical across counts (below).
FEM_CHAPTER_TESTS("09", "[ch09]")

TEST_CASE("ch09: the system equals chapter 08's, by either element pass", "[ch09]") {
  const Scene scene = test::driven_scene();
  const ThreadCountScope threads(openmp_enabled() ? 2 : 1);
  ch08::ElementKernelsStepper serial(scene, test::tight_solver());
  ch09::ThreadsStepper colouring(scene, test::tight_solver(),
                                 ch09::parallelism(ch09::ElementParallelism::colouring));
  ch09::ThreadsStepper gather(scene, test::tight_solver(),
                              ch09::parallelism(ch09::ElementParallelism::gather));
  CHECK(colouring.elements().colours() > 1);
  State state = rest_state(scene);
  for (int k = 0; k < 5; ++k) {
    State a = state, b = state, c = state;  // the same input state: only rounding may differ
    serial.step(a);
    colouring.step(b);
    gather.step(c);
    const Eigen::SparseMatrix<double> A = serial.system_matrix().to_sparse();
    CHECK((A - colouring.system_matrix().to_sparse()).norm() <= 1e-13 * A.norm());
    // The gather adds each block's terms in element order, as the serial pass: the same bits.
    CHECK((A - gather.system_matrix().to_sparse()).norm() == 0.0);
    const Eigen::VectorXd& rhs = serial.system_rhs();
    CHECK((rhs - colouring.system_rhs()).norm() <= 1e-13 * rhs.norm());
    CHECK(bit_identical(gather.system_rhs(), rhs));
    state = a;
  }
}

TEST_CASE("ch09: the parallel PCG solves the system to the tolerance, on any thread count",
          "[ch09]") {
  const Scene scene = test::driven_scene();
  ch09::ThreadsStepper stepper(scene, {});
  State state = rest_state(scene);
  for (int k = 0; k < 3; ++k) stepper.step(state);
  const ch09::BlockSparseMatrix& A = stepper.system_matrix();
  const Eigen::VectorXd& b = stepper.system_rhs();
  Eigen::VectorXd first;
  for (const int threads : thread_counts()) {
    const ThreadCountScope scope(threads);
    ch09::ParallelPcg pcg(A, scene.constraints);
    const ch08::PartSetup setup{stepper.scene(), stepper.model(), stepper.system(),
                                stepper.settings()};
    ch08::AssembledProduct product(setup, {});
    ch09::JacobiOnChunks block_jacobi(setup, {});
    Eigen::VectorXd y = Eigen::VectorXd::Zero(b.size()), Ay(b.size());
    const SolveStats result = pcg.solve(A, product, block_jacobi, b, test::tight_solver(), y);
    A.multiply(y, Ay);
    INFO(threads << " threads: " << result.iterations << " iterations");
    CHECK(result.converged);
    CHECK((b - Ay).norm() <= 1e-11 * b.norm());
    if (first.size() == 0) first = y;
    CHECK(bit_identical(y, first));
  }
}

TEST_CASE("ch09: zero heap allocations per step after the first, with 2 threads", "[ch09][alloc]") {
  FEM_REQUIRE_ALLOCATION_COUNTER();
  // The counter sees every thread's allocations. OpenMP's set-up, the first time a region
  // has a team of a new size (libgomp's threads and its team structure), falls in the first
  // step, with the stepper's own first-step sizing; libgomp keeps that team for the next
  // regions of the same size, so the steps after it allocate nothing.
  const int threads = openmp_enabled() ? 2 : 1;
  const ThreadCountScope scope(threads);
  for (const Scene& scene : {test::test_scene("cantilever"), test::driven_scene()}) {
    INFO(scene.name << ", " << threads << " threads");
    CHECK(test::allocations_per_step("09", scene) == 0);
  }
}

TEST_CASE("ch09: one thread opens no parallel region, so it allocates nothing either",
          "[ch09][alloc]") {
  FEM_REQUIRE_ALLOCATION_COUNTER();
  // libgomp frees a team of one thread at the end of each region (gomp_team_end): a region
  // per phase would cost a malloc each. run_parallel calls the body directly instead.
  const ThreadCountScope scope(1);
  CHECK(test::allocations_per_step("09", test::driven_scene()) == 0);
}

TEST_CASE("ch09: the adaptive team switches to one thread when that is faster, and back",
          "[ch09]") {
  // Synthetic step times: the team's choice depends on nothing else.
  const auto run = [](ch09::AdaptiveTeam& team, int steps, double two, double one) {
    int on_one = 0;
    for (int k = 0; k < steps; ++k) {
      const int n = team.next(2);
      on_one += n == 1;
      team.record(n == 1 ? one : two);
    }
    return on_one;
  };
  ch09::AdaptiveTeam team;
  // Two threads twice as fast: one probe step on one thread now and then, fewer and fewer.
  CHECK(run(team, 1000, 1.0, 2.0) <= 8);  // probes after 8, 16, 32, ..., 256, 256 steps
  CHECK(team.switches() == 0);
  // A busy machine: two threads five times slower. The usual time jumps, the next step probes
  // one thread and switches; then a probe on two threads now and then.
  CHECK(run(team, 1000, 5.0, 1.0) >= 985);
  CHECK(team.switches() == 1);
  // The machine free again: the next periodic probe on two threads switches back.
  CHECK(run(team, 1000, 1.0, 2.0) <= 270);
  CHECK(team.switches() == 2);
  ch09::AdaptiveTeam off;
  off.set_enabled(false);
  CHECK(run(off, 100, 5.0, 1.0) == 0);
  CHECK(off.next(1) == 1);
}

namespace {

// The synchronizations the counter saw during f() (chapter 09's SyncCounts).
template <class F>
Synchronizations syncs_during(F&& f) {
  const Synchronizations before = ch09::sync_counts().snapshot();
  f();
  const Synchronizations after = ch09::sync_counts().snapshot();
  return {after.regions - before.regions, after.barriers - before.barriers};
}

}  // namespace

TEST_CASE("ch09: each phase counts its own synchronizations, and they add up to the step's",
          "[ch09]") {
  // PhaseTimer reads chapter 09's counter through the hook that parallel.hpp sets: the phases
  // cover the step but for the update (no wait), so their counts sum to the step's, and the
  // step's is what the counter saw. Chapters before 09 open no region and meet no barrier.
  REQUIRE(sync_count_hook != nullptr);
  const Scene scene = test::test_scene("cantilever");
  const ThreadCountScope scope(openmp_enabled() ? 2 : 1);
  for (const ChapterInfo& chapter : chapters()) {
    if (!chapter.variant_of.empty()) continue;
    INFO(chapter.id);
    // The team of two on every step: the adaptive team off for the steppers made here.
    ::setenv("FEM_ADAPTIVE_TEAM", "0", 1);
    const auto stepper = chapter.make(scene, {});
    ::unsetenv("FEM_ADAPTIVE_TEAM");
    State state = rest_state(scene);
    stepper->step(state);
    const Synchronizations seen = syncs_during([&] { stepper->step(state); });
    const StepProfile& p = stepper->profile();
    long long regions = 0, barriers = 0;
    p.for_each_phase([&](const char* name, const PhaseCost& cost) {
      if (std::string(name) == "step") return;
      regions += cost.regions;
      barriers += cost.barriers;
    });
    CHECK(regions == p.step.regions);
    CHECK(barriers == p.step.barriers);
    CHECK(p.step.regions == seen.regions);
    CHECK(p.step.barriers == seen.barriers);
    if (!stepper->uses_threads()) {
      CHECK(p.step.barriers == 0);
      CHECK(p.step.regions == 0);
      continue;
    }
    // Every PCG iteration ends worksharing loops (a barrier each): at least one per iteration.
    CHECK(p.solve.barriers >= p.cg_iterations);
    CHECK(p.forces.barriers >= 1);
    if (openmp_enabled()) CHECK(p.solve.regions >= 1);
  }
}

TEST_CASE("ch09: --threads style errors: a count below 1 is refused", "[ch09]") {
  CHECK_THROWS_AS(set_threads(0), std::invalid_argument);
  if (!openmp_enabled()) CHECK_THROWS_AS(set_threads(2), std::invalid_argument);
}

namespace {

// Kinetic + elastic + gravitational energy; its change from rest stays bounded when the body
// neither gains energy from nowhere nor diverges.
double total_energy(const Model& model, const Scene& scene, const State& state) {
  const double kinetic = 0.5 * state.v.dot(model.lumped_mass.cwiseProduct(state.v));
  return kinetic + elastic_energy(model, scene, state.x) - model.gravity_force.dot(state.x);
}

struct SoakResult {
  State state;
  double max_energy_early = 0.0, max_energy = 0.0;
  int not_converged = 0;
  std::string diverged;
};

// A few thousand steps under the jumping mouse spring (support.hpp), a new node every 7 steps.
SoakResult soak(const std::string& chapter, const Scene& scene, int threads, int steps) {
  const ThreadCountScope scope(threads);
  auto stepper = make_stepper(chapter, scene, {});
  const Model model(scene);
  test::JumpingMouse mouse(scene, 7);
  SoakResult out;
  out.state = rest_state(scene);
  const double rest_energy = total_energy(model, scene, out.state);
  out.diverged = test::soak_under_mouse(*stepper, mouse, out.state, steps, [&](int k) {
    out.not_converged += stepper->profile().converged ? 0 : 1;
    if (k % 20 == 0) {
      const double energy = std::abs(total_energy(model, scene, out.state) - rest_energy);
      out.max_energy = std::max(out.max_energy, energy);
      // The spring's first 300 steps (a tenth of the full soak, however many steps run).
      if (k < 300) out.max_energy_early = out.max_energy;
    }
  });
  return out;
}

}  // namespace

TEST_CASE("ch09: soak, thousands of steps under a random mouse spring, chapters 07 on",
          "[ch09][soak]") {
  const Scene scene = test::test_scene("cantilever");
  const int steps = test::soak_steps(3000);
  std::vector<std::pair<std::string, int>> runs = {{"07", 1}, {"08", 1}, {"09", 1}};
  if (openmp_enabled()) runs.push_back({"09", 2});
  std::vector<SoakResult> results;
  for (const auto& [chapter, threads] : runs) {
    results.push_back(soak(chapter, scene, threads, steps));
    const SoakResult& r = results.back();
    INFO("chapter " << chapter << " on " << threads << " threads");
    CHECK(r.diverged.empty());
    CHECK(r.not_converged == 0);
    // Bounded: the energy of the whole run stays within a small multiple of what the spring
    // put in during its first 300 steps (damping takes out what the spring puts in).
    CHECK(r.max_energy_early > 0.0);
    CHECK(r.max_energy < 10.0 * r.max_energy_early);
  }
  if (openmp_enabled()) {
    CHECK(bit_identical(results[2].state.x, results[3].state.x));
    CHECK(bit_identical(results[2].state.v, results[3].state.v));
  }
}
