// The checks every chapter passes, registered once per chapter the build found (the
// registry is generated from chapters/*/), so a new chapter or a student's variant made with
// ./tutorial.sh variant is tested without a line of test code: it matches chapter 01 on both
// scenes, its allocations per step are deterministic (none if its original has none), its
// state is the same to the last bit on 1, 2 and 3 threads, and it meets its constraints as
// exactly as its original. Labels: "chapters", and the chapter's own (ch06, ch06_NAME).
#include <algorithm>
#include <string>
#include <utility>

#include "catch2_compat.hpp"
#include "common/threads.hpp"
#include "support.hpp"

namespace {

using namespace fem;

void matches_ch01(const ChapterInfo& chapter) {
  for (const char* name : {"cantilever", "sliding"})
    test::check_matches_ch01(chapter.id, test::test_scene(name));
}

void allocations(const ChapterInfo& chapter) {
  FEM_REQUIRE_ALLOCATION_COUNTER();
  for (const char* name : {"cantilever", "sliding"}) {
    const Scene scene = test::test_scene(name);
    const long long count = test::allocations_per_step(chapter.id, scene);
    INFO(chapter.id << " on " << name << ": " << count << " allocations per step (-1: not the "
                    << "same every step)");
    CHECK(count >= 0);
    // The chapters from 06 on allocate nothing; a variant of one must keep it that way.
    if (!chapter.variant_of.empty() && test::allocations_per_step(chapter.variant_of, scene) == 0)
      CHECK(count == 0);
  }
}

// The same state to the last bit after 30 steps on 1, 2 and 3 threads: chapter 09's rule
// (fixed chunks, sums in a fixed order) for every chapter that uses threads, its variants
// included; a single-threaded chapter runs on one thread whatever the count (on_one_thread).
void same_state_on_any_thread_count(const ChapterInfo& chapter) {
  const Scene scene = test::test_scene("sliding");
  const auto run_on = [&](int threads) {
    const ThreadCountScope scope(threads);
    return test::run(chapter.id, scene, 30);
  };
  const State one = run_on(1);
  REQUIRE((one.x - rest_state(scene).x).cwiseAbs().maxCoeff() > 1e-4);  // it moved
  if (!openmp_enabled()) {
    SUCCEED("built without OpenMP: one thread only");
    return;
  }
  for (const int threads : {2, 3}) {
    const State other = run_on(threads);
    INFO(chapter.id << " on " << threads << " threads against 1: max |dx| "
                    << (other.x - one.x).cwiseAbs().maxCoeff() << ", max |dv| "
                    << (other.v - one.v).cwiseAbs().maxCoeff());
    CHECK((other.x.array() == one.x.array()).all());
    CHECK((other.v.array() == one.v.array()).all());
  }
}

// The largest velocity component, over 30 steps of the driven scene (every filter case, a
// prescribed velocity on every constrained node) at the default tolerance, that a step leaves
// in a constrained direction other than the prescribed one: |(I - S_i)(v_i - v_target,i)|,
// relative to the largest velocity. PPCG (chapter 06 on) keeps the iterates in the filtered
// subspace, so this is rounding; Eigen's CG on the filtered system (01-05) reaches it only
// to the tolerance.
double constraint_violation(const std::string& chapter) {
  const Scene scene = test::driven_scene();
  auto stepper = make_stepper(chapter, scene, {});
  State state = rest_state(scene);
  double worst = 0.0;
  for (int k = 0; k < 30; ++k) {
    stepper->step(state);
    const double scale = state.v.cwiseAbs().maxCoeff();
    for (const auto& c : scene.constraints) {
      const Eigen::Vector3d off = (Eigen::Matrix3d::Identity() - c.filter) *
                                  (state.v.segment<3>(3 * c.node) - c.target_velocity);
      worst = std::max(worst, off.cwiseAbs().maxCoeff() / scale);
    }
  }
  return worst;
}

// Every chapter meets its constraints to the solver's tolerance; a variant of a chapter that
// meets them to rounding (PPCG: chapter 06's exercise 3 removes its filters) must too.
void constraints_hold(const ChapterInfo& chapter) {
  constexpr double kRounding = 1e-12;
  const double violation = constraint_violation(chapter.id);
  INFO(chapter.id << ": largest constrained velocity component off its prescribed value, "
                  << "relative to the largest velocity: " << violation);
  CHECK(violation <= 10.0 * SolverSettings{}.tolerance);
  if (!chapter.variant_of.empty()) {
    const double original = constraint_violation(chapter.variant_of);
    INFO("its original " << chapter.variant_of << ": " << original);
    if (original <= kRounding) CHECK(violation <= kRounding);
  }
}

// One test case per chapter and check, made at run time from the registry.
const bool registered = [] {
  for (const ChapterInfo& chapter : chapters()) {
    const std::pair<const char*, void (*)(const ChapterInfo&)> checks[] = {
        {"matches chapter 01 on both scenes over 50 steps", matches_ch01},
        {"allocations per step are the same every step", allocations},
        {"the same state to the last bit on 1, 2 and 3 threads", same_state_on_any_thread_count},
        {"constrained velocities are the prescribed ones", constraints_hold}};
    for (const auto& [what, check] : checks)
      test::register_test_case(
          chapter.id + ": " + what, "[every_chapter][" + chapter.id + "]",
          [check = check, &chapter] { check(chapter); }, Catch::SourceLineInfo(__FILE__, __LINE__));
  }
  return true;
}();

}  // namespace
