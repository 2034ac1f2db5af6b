// Chapter 14: the stepper whose V-cycle runs its finest level in pair lanes. Its preconditioner
// is chapter 12's float V-cycle to float rounding (the lanes' products are the padded columns'
// to the bit, their update rounds once where the compiler fuses: ch14_kernels.cpp), the same
// bits on 1, 2 and 3 threads; the solve takes chapter 12's iterations; the counts the roofline
// prices read the lanes' bytes; a soak under a jumping mouse spring stays bounded and the same
// on 1 and 2 threads; the stepper matches chapter 01 and allocates nothing per step.
#include <algorithm>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "catch2_compat.hpp"
#include "chapters/09_threads/parallel.hpp"
#include "chapters/12_half_the_bytes/stepper.hpp"
#include "chapters/12_half_the_bytes/work.hpp"
#include "chapters/14_every_lane/stepper.hpp"
#include "chapters/14_every_lane/work.hpp"
#include "common/threads.hpp"
#include "support.hpp"

using namespace fem;

FEM_CHAPTER_TESTS("14", "[ch14]")

namespace {

std::vector<int> thread_counts() {
  return openmp_enabled() ? std::vector<int>{1, 2, 3} : std::vector<int>{1};
}

// s = M r by chapter 12's float V-cycle and by the lanes' one built on the same hierarchy, for
// random r, on the system of a few steps of chapter 12, applied inside one team as the PCG
// applies them.
struct Applied {
  Eigen::VectorXd twelve, lanes;
};
// layout: the finest level's, forced; none: the one the cycle measures faster.
Applied apply_both(const Scene& scene, int threads, std::optional<ch14::Layout> layout) {
  ch12::HalfBytesStepper stepper(scene, {});
  State state = rest_state(scene);
  for (int k = 0; k < 3; ++k) stepper.step(state);
  auto& reduced = stepper.preconditioner().v_cycle();
  ch14::LaneVCycle lanes(reduced, stepper.preconditioner().multigrid(), layout);
  const ThreadCountScope scope(threads);
  const Eigen::Index n = stepper.system_rhs().size();
  std::mt19937 rng(14);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  Eigen::VectorXd r(n);
  for (Eigen::Index k = 0; k < n; ++k) r[k] = uniform(rng);
  Applied out{Eigen::VectorXd::Zero(n), Eigen::VectorXd::Zero(n)};
  // Measured: the trial in the first prepare, then prepares in the chosen layout.
  std::vector<Eigen::VectorXd> cycles(layout ? 2 : 6, Eigen::VectorXd::Zero(n));
  ch09::run_parallel([&] {
    for (std::size_t k = 0; k < cycles.size(); k += 2) {
      lanes.prepare(stepper.system_matrix());
      lanes.apply(r, cycles[k]);
      lanes.apply(r, cycles[k + 1]);
    }
    reduced.apply(r, out.twelve);
  });
  out.lanes = cycles.front();
  for (const Eigen::VectorXd& s : cycles) CHECK((s.array() == out.lanes.array()).all());
  if (layout) CHECK(lanes.layout() == *layout);
  // Measured: the layout timed faster on this team is the one that ran last.
  if (!layout) CHECK(lanes.measured(threads) == std::optional<ch14::Layout>(lanes.layout()));
  return out;
}

}  // namespace

// Padded, packed, or the one the cycle measures faster on each team: the same bits, so that the
// choice (a timing, which may differ from run to run) changes the time only.
TEST_CASE(
    "ch14: the lanes' V-cycle, padded, packed or measured, is chapter 12's to float rounding, "
    "the same bits in every layout and on 1, 2, 3 threads",
    "[ch14]") {
  const Scene scene = test::test_scene("cantilever");
  const Eigen::VectorXd padded = apply_both(scene, 1, ch14::Layout::padded).lanes;
  for (const std::optional<ch14::Layout> layout :
       {std::optional<ch14::Layout>(ch14::Layout::padded),
        std::optional<ch14::Layout>(ch14::Layout::packed), std::optional<ch14::Layout>()}) {
    INFO((!layout ? "measured" : *layout == ch14::Layout::padded ? "padded" : "packed"));
    const Applied first = apply_both(scene, 1, layout);
    CHECK((first.lanes.array() == padded.array()).all());
    REQUIRE(first.lanes.allFinite());
    const double scale = first.twelve.cwiseAbs().maxCoeff();
    REQUIRE(scale > 0.0);
    // A float V-cycle's own rounding: a few float epsilons of the largest entry, times the
    // levels' sums; the lanes differ from it only in where the update rounds.
    const double difference = (first.lanes - first.twelve).cwiseAbs().maxCoeff();
    INFO("largest difference " << difference << " of " << scale);
    CHECK(difference < 1e-4 * scale);
    for (const int threads : thread_counts()) {
      const Applied again = apply_both(scene, threads, layout);
      INFO(threads << " threads");
      CHECK((again.lanes.array() == first.lanes.array()).all());
    }
  }
}

// The trial's bookkeeping, whatever the timings say: the first prepare on a team size times
// both layouts (five fills of each) and runs the faster from that prepare on, another team
// size has its own trial, a forced layout runs no trial, and force() acts from the next prepare.
TEST_CASE(
    "ch14: the layout trial runs in the first prepare on each team size, times five fills of "
    "each layout, and force() acts from the next prepare",
    "[ch14]") {
  const Scene scene = test::test_scene("cantilever");
  ch12::HalfBytesStepper stepper(scene, {});
  State state = rest_state(scene);
  for (int k = 0; k < 3; ++k) stepper.step(state);
  const auto make = [&](std::optional<ch14::Layout> forced) {
    return ch14::LaneVCycle(stepper.preconditioner().v_cycle(),
                            stepper.preconditioner().multigrid(), forced);
  };
  ch14::LaneVCycle lanes = make(std::nullopt);
  REQUIRE(lanes.lanes());
  const Eigen::VectorXd r = Eigen::VectorXd::Ones(stepper.system_rhs().size());
  Eigen::VectorXd s(r.size());
  const auto steps = [&](ch14::LaneVCycle& cycle, int threads) {
    const ThreadCountScope team(threads);
    ch14::Layout ran{};
    ch09::run_parallel([&] {
      cycle.prepare(stepper.system_matrix());
      cycle.apply(r, s);
      ch09::on_one_thread(true, [&] { ran = cycle.layout(); });
    });
    return ran;
  };
  const auto timed = [&](const ch14::LaneVCycle& cycle, int threads) {
    const ch14::LaneVCycle::Seconds& seconds = cycle.trial_seconds(threads);
    return std::all_of(seconds.begin(), seconds.end(), [](double t) { return t > 0.0; });
  };
  CHECK(!lanes.measured(1));
  CHECK(!timed(lanes, 1));
  const ch14::Layout first = steps(lanes, 1);
  REQUIRE(lanes.measured(1));
  CHECK(first == *lanes.measured(1));
  CHECK(timed(lanes, 1));
  CHECK(!lanes.measured(2));
  const ch14::LaneVCycle::Seconds once = lanes.trial_seconds(1);
  CHECK(steps(lanes, 1) == first);
  CHECK(lanes.trial_seconds(1) == once);  // timed once per team size
  using L = ch14::Layout;
  const L other = first == L::padded ? L::packed : L::padded;
  lanes.force(other);
  CHECK(lanes.layout() == first);
  CHECK(steps(lanes, 1) == other);
  lanes.force(std::nullopt);
  CHECK(steps(lanes, 1) == first);
  if (max_threads() >= 2) {
    const L two = steps(lanes, 2);
    REQUIRE(lanes.measured(2));
    CHECK(two == *lanes.measured(2));
    CHECK(timed(lanes, 2));
    CHECK(lanes.trial_seconds(1) == once);
  }
  ch14::LaneVCycle forced = make(L::packed);
  CHECK(steps(forced, 1) == L::packed);
  CHECK(!forced.measured(1));
  CHECK(!timed(forced, 1));
}

TEST_CASE("ch14: chapter 12's iterations at 1e-4, at most one more, and 1e-10 still reached",
          "[ch14]") {
  for (const double tolerance : {1e-4, 1e-10}) {
    for (const Scene& scene : test::equivalence_scenes()) {
      SolverSettings settings;
      settings.tolerance = tolerance;
      ch12::HalfBytesStepper twelve(scene, settings);
      ch14::EveryLaneStepper fourteen(scene, settings);
      State a = rest_state(scene), b = a;
      int worst = 0;
      for (int k = 0; k < 20; ++k) {
        twelve.step(a);
        fourteen.step(b);
        REQUIRE(fourteen.profile().converged);
        worst = std::max(worst, fourteen.profile().cg_iterations - twelve.profile().cg_iterations);
      }
      INFO(scene.name << ", tolerance " << tolerance << ": most extra iterations " << worst);
      CHECK(worst <= 1);
      CHECK((b.x - a.x).cwiseAbs().maxCoeff() < 1e3 * tolerance);
    }
  }
}

TEST_CASE("ch14: zero heap allocations per step after the first, with 2 threads", "[ch14]") {
  FEM_REQUIRE_ALLOCATION_COUNTER();
  const ThreadCountScope two(openmp_enabled() ? 2 : 1);
  for (const Scene& scene : test::equivalence_scenes()) {
    INFO(scene.name);
    CHECK(test::allocations_per_step("14", scene) == 0);
  }
}

TEST_CASE("ch14: the roofline's count of the cycle reads the lanes' bytes, chapter 12's otherwise",
          "[ch14]") {
  const Scene scene = test::test_scene("cantilever");
  ch12::HalfBytesStepper twelve(scene, {});
  ch14::EveryLaneStepper fourteen(scene, {});
  State a = rest_state(scene), b = a;
  twelve.step(a);
  fourteen.step(b);
  const ch01::MeshSizes m = ch01::mesh_sizes(scene);
  const WorkCounts counts{};
  const ch08::WorkInput in12{m, twelve.system_matrix(), scene, counts, {}};
  const ch08::WorkInput in14{m, fourteen.system_matrix(), scene, counts, {}};
  const ch08::PreconditionerWork w12 = preconditioner_work(twelve.preconditioner(), in12);
  const ch08::PreconditionerWork w14 = preconditioner_work(fourteen.preconditioner(), in14);
  const ch14::LaneVCycle& cycle = fourteen.preconditioner().lane_v_cycle();
  const double lanes_step_bytes =
      cycle.with_fine_level([](const auto& fine) { return fine.smoothing_work().bytes_read; });
  const double lanes_bytes =
      cycle.with_fine_level([](const auto& fine) { return fine.blocks.bytes(); });
  const double products = ch10::smoother_products(fourteen.preconditioner().multigrid());
  REQUIRE(w12.apply.parts.size() == w14.apply.parts.size());
  for (std::size_t k = 0; k < w12.apply.parts.size(); ++k) {
    const PhaseWork &p12 = w12.apply.parts[k], &p14 = w14.apply.parts[k];
    INFO(p14.phase);
    CHECK(p12.phase == p14.phase);
    CHECK(p12.flops_float == p14.flops_float);
    if (p14.phase != "level 0 smoothing and residual") {
      CHECK(p12.bytes_read == p14.bytes_read);
      continue;
    }
    // Per product, the bytes of one smoothing step on the lanes (LaneLevel::smoothing_work).
    CHECK(p14.bytes_read == Approx(products * lanes_step_bytes).epsilon(1e-12));
    CHECK(p14.bytes_read > p12.bytes_read);  // padding lanes and an offset a block
  }
  CHECK(w14.prepare_written == Approx(w12.prepare_written + lanes_bytes));
}

TEST_CASE("ch14: the printed summary names the lanes' part and chapter 12's", "[ch14]") {
  const Scene scene = test::test_scene("cantilever");
  const ch14::EveryLaneStepper stepper(scene, {});
  std::ostringstream out;
  out << static_cast<const Stepper&>(stepper);
  const std::string text = out.str();
  ch14::EveryLaneStepper::for_each_part([&](const ch08::PartName& part) {
    INFO(part.role);
    CHECK(text.find(std::string(part.role) + ": " + part.name + " (" + std::string(part.chapter) +
                    ")") != std::string::npos);
  });
  CHECK(text.find("(14_every_lane)") != std::string::npos);
  CHECK(text.find("MiB against a last cache of") != std::string::npos);
  // Each part formats its own numbers: none leaves the stream's precision changed for the next.
  CHECK(text.find("e+") == std::string::npos);
  CHECK(text.find("finest level in pair lanes") != std::string::npos);
  // The test scene's A fits in any last cache; a machine that does not say (0) fetches ahead.
  const bool ahead = stepper.elements().fetches_ahead();
  CHECK(ahead == (last_cache_bytes() == 0));
  CHECK(text.find(ahead ? "the next batch fetched ahead" : "no fetching ahead") !=
        std::string::npos);
}

TEST_CASE(
    "ch14: the element pass fills chapter 12's A and b to the bit, fetching ahead or not, on 1, "
    "2 and 3 threads",
    "[ch14]") {
  for (const Scene& scene : test::equivalence_scenes()) {
    for (const int threads : thread_counts()) {
      const ThreadCountScope team(threads);
      ch12::HalfBytesStepper twelve(scene, {});
      State a = rest_state(scene);
      twelve.step(a);
      for (const long long cache_bytes : {0LL, 1LL << 40}) {
        INFO(scene.name << ", " << threads << " threads, last cache " << cache_bytes);
        ch08::StepParams<ch14::EveryLane> params;
        params.elements.cache_bytes = cache_bytes;
        ch14::EveryLaneStepper fourteen(scene, {}, params);
        CHECK(fourteen.elements().fetches_ahead() == (cache_bytes == 0));
        State b = rest_state(scene);
        fourteen.step(b);
        const auto& A12 = twelve.system_matrix().blocks;
        const auto& A14 = fourteen.system_matrix().blocks;
        REQUIRE(A12.size() == A14.size());
        bool same = true;
        for (std::size_t k = 0; k < A12.size(); ++k)
          same = same && (A12[k].array() == A14[k].array()).all();
        CHECK(same);
        CHECK((twelve.system_rhs().array() == fourteen.system_rhs().array()).all());
      }
    }
  }
}

TEST_CASE("ch14: soak, thousands of steps under a jumping mouse spring, 1 and 2 threads",
          "[ch14][soak]") {
  test::check_soak<ch14::EveryLaneStepper>(test::test_scene("cantilever"));
}
