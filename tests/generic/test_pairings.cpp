// Any solver with any preconditioner, and any product (chapter 08's contract): every solver
// part of the course (08, 09, 13) in the recipe of the chapter that teaches each
// preconditioner part (08, 09, 10, 12 in float and in double, 13, 14) in place of that
// chapter's solver, and chapter 14's product in pair lanes in every one of those recipes.
// Each converges at every step, its iterations within one a step of the teaching chapter's
// (the same PCG in exact arithmetic: only rounding tells the solvers apart), and its state
// within the solver's tolerance of the teaching chapter's. Label "chapters".
#include <Eigen/Core>
#include <cmath>
#include <string>

#include "catch2_compat.hpp"
#include "chapters/08_element_kernels/stepper.hpp"
#include "chapters/09_threads/stepper.hpp"
#include "chapters/10_multigrid/stepper.hpp"
#include "chapters/12_half_the_bytes/stepper.hpp"
#include "chapters/13_fewer_waits/stepper.hpp"
#include "chapters/14_every_lane/lane_product.hpp"
#include "chapters/14_every_lane/stepper.hpp"
#include "support.hpp"

namespace {

using namespace fem;

// A recipe with another solver, or another product, in place of its own.
template <class Recipe, class S>
struct WithSolver : Recipe {
  using Solver = S;
};
template <class Recipe, class P>
struct WithProduct : Recipe {
  using Product = P;
};
// Chapter 12's recipe with its V-cycle in double arithmetic on the float numbers.
struct HalfTheBytesInDouble : ch12::HalfTheBytes {
  using Preconditioner = ch12::ReducedMultigrid<double>;
};

struct Run {
  State state;
  int iterations = 0;  // over every step
  bool converged = true;
};

template <class Recipe>
Run run(const Scene& scene, int steps) {
  ch08::StepOf<Recipe> stepper(scene, test::tight_solver());
  Run r{rest_state(scene)};
  for (int k = 0; k < steps; ++k) {
    stepper.step(r.state);
    r.iterations += stepper.profile().cg_iterations;
    r.converged = r.converged && stepper.profile().converged;
  }
  return r;
}

constexpr int kSteps = 5;

// The pairing's run against the teaching chapter's.
template <class Teaching, class Pairing>
void check_pairing(const Scene& scene, const Run& teaching, const std::string& name) {
  const Run pairing = run<Pairing>(scene, kSteps);
  const double motion = (teaching.state.x - rest_state(scene).x).cwiseAbs().maxCoeff();
  const double dx = (pairing.state.x - teaching.state.x).cwiseAbs().maxCoeff();
  INFO(name << ": " << pairing.iterations << " iterations against " << teaching.iterations << " in "
            << kSteps << " steps; max |dx| " << dx << " of a motion of " << motion);
  CHECK(pairing.converged);
  CHECK(std::abs(pairing.iterations - teaching.iterations) <= kSteps);
  CHECK(dx <= 1e-6 * motion);
}

// Every solver, and the product in lanes, in the recipe that teaches a preconditioner.
template <class Teaching>
void check_every_solver(const std::string& teaching_name) {
  const Scene scene = test::driven_scene();
  const Run teaching = run<Teaching>(scene, kSteps);
  REQUIRE(teaching.converged);
  check_pairing<Teaching, WithSolver<Teaching, ch08::SerialPcg>>(
      scene, teaching, teaching_name + " with chapter 08's solver");
  check_pairing<Teaching, WithSolver<Teaching, ch09::ParallelPcgSolver>>(
      scene, teaching, teaching_name + " with chapter 09's solver");
  check_pairing<Teaching, WithSolver<Teaching, ch13::SingleReductionSolver>>(
      scene, teaching, teaching_name + " with chapter 13's solver");
  check_pairing<Teaching, WithProduct<Teaching, ch14::LaneProduct>>(
      scene, teaching, teaching_name + " with chapter 14's product in lanes");
}

}  // namespace

TEST_CASE("pairings: every solver with chapter 08's block Jacobi", "[chapters][pairings]") {
  check_every_solver<ch08::ElementKernels>("chapter 08's recipe");
}

TEST_CASE("pairings: every solver with chapter 09's block Jacobi on the chunks",
          "[chapters][pairings]") {
  check_every_solver<ch09::Threads>("chapter 09's recipe");
}

TEST_CASE("pairings: every solver with chapter 10's V-cycle", "[chapters][pairings]") {
  check_every_solver<ch10::MultigridRecipe>("chapter 10's recipe");
}

TEST_CASE("pairings: every solver with chapter 12's V-cycle in float", "[chapters][pairings]") {
  check_every_solver<ch12::HalfTheBytes>("chapter 12's recipe");
}

TEST_CASE("pairings: every solver with chapter 12's V-cycle in double on float",
          "[chapters][pairings]") {
  check_every_solver<HalfTheBytesInDouble>("chapter 12's recipe in double");
}

TEST_CASE("pairings: every solver with chapter 13's fused V-cycle", "[chapters][pairings]") {
  check_every_solver<ch13::FewerWaits>("chapter 13's recipe");
}

TEST_CASE("pairings: every solver with chapter 14's V-cycle in lanes", "[chapters][pairings]") {
  check_every_solver<ch14::EveryLane>("chapter 14's recipe");
}

// The recipe's contract at compile time: a whole recipe passes check_recipe, and each of the
// course's recipes is whole (a recipe missing a role or a member is the compile-fail test
// "pairings: a recipe missing a role or a member fails with one sentence").
static_assert(ch08::recipe_is_whole<ch13::FewerWaits>());
static_assert(
    ch08::recipe_is_whole<WithSolver<ch08::ElementKernels, ch13::SingleReductionSolver>>());
static_assert(!ch08::recipe_is_whole<int>());
