// Chapter 12: the V-cycle on float numbers is still what PCG's theory needs (symmetric to
// the rounding of its arithmetic, positive definite on the filtered space), it holds exactly
// chapter 10's numbers rounded to float, it costs at most one iteration more than chapter
// 11's double V-cycle at the default tolerance, the solve still reaches a tight tolerance, and
// the stepper matches chapter 01, allocates nothing and is bit-identical on 1, 2 and 3 threads
// (the generic tests).
#include <cmath>
#include <random>

#include "catch2_compat.hpp"
#include "chapters/08_element_kernels/element_kernels.hpp"
#include "chapters/10_multigrid/report.hpp"
#include "chapters/10_multigrid/stepper.hpp"
#include "chapters/11_node_order/stepper.hpp"
#include "chapters/12_half_the_bytes/element_batch.hpp"
#include "chapters/12_half_the_bytes/stepper.hpp"
#include "common/model.hpp"
#include "common/threads.hpp"
#include "support.hpp"

using namespace fem;

FEM_CHAPTER_TESTS("12", "[ch12]")

namespace {

// Chapter 12's recipe with its float numbers widened to double in registers.
struct Widened : ch12::HalfTheBytes {
  using Preconditioner = ch12::ReducedMultigrid<double>;
};

Eigen::VectorXd filtered_random(const Scene& scene, Eigen::Index size) {
  Eigen::VectorXd v = Eigen::VectorXd::Random(size);
  for (const auto& c : scene.constraints)
    v.segment<3>(3 * c.node) = c.filter * v.segment<3>(3 * c.node);
  return v;
}

// Three levels on the 190-node test mesh, small row blocks (as chapter 10's tests).
ch10::MultigridStepperSettings three_levels() {
  ch10::MultigridStepperSettings s;
  s.multigrid.max_coarse_dofs = 24;
  s.multigrid.rows.block_rows = 4;
  return s;
}

// x^T M y - y^T M x against sqrt(x^T M x y^T M y), over five pairs of filtered vectors; the
// smallest x^T M x / x^T x.
template <class Real>
std::pair<double, double> asymmetry_and_positivity(const Scene& scene) {
  ch10::MultigridStepper stepper(scene, {},
                                 ch10::multigrid_params<ch10::MultigridRecipe>(three_levels()));
  State state = rest_state(scene);
  for (int k = 0; k < 3; ++k) stepper.step(state);
  REQUIRE(stepper.preconditioner().multigrid().levels() == 3);
  ch12::ReducedVCycle<Real> v_cycle(stepper.preconditioner().multigrid());
  v_cycle.prepare(stepper.system_matrix());
  std::srand(12);
  const Eigen::Index n = stepper.system_rhs().size();
  Eigen::VectorXd Mx(n), My(n);
  double asymmetry = 0.0, positivity = INFINITY;
  for (int trial = 0; trial < 5; ++trial) {
    const Eigen::VectorXd x = filtered_random(scene, n), y = filtered_random(scene, n);
    v_cycle.apply(x, Mx);
    v_cycle.apply(y, My);
    asymmetry =
        std::max(asymmetry, std::abs(x.dot(My) - y.dot(Mx)) / std::sqrt(x.dot(Mx) * y.dot(My)));
    positivity = std::min({positivity, x.dot(Mx) / x.squaredNorm(), y.dot(My) / y.squaredNorm()});
  }
  return {asymmetry, positivity};
}

}  // namespace

TEST_CASE("ch12: the float V-cycle is symmetric to its rounding and positive definite", "[ch12]") {
  // In float arithmetic the two sides of x^T M y = y^T M x round differently: symmetric to
  // float's 6e-8 times the cycle's few hundred operations. Widened to double, the float
  // numbers form an exactly symmetric operator (P^T is P transposed entry by entry, the
  // matrices stay symmetric when rounded): chapter 10's 1e-12 holds.
  for (const Scene& scene : test::equivalence_scenes()) {
    const auto [single_asymmetry, single_positivity] = asymmetry_and_positivity<float>(scene);
    const auto [double_asymmetry, double_positivity] = asymmetry_and_positivity<double>(scene);
    INFO(scene.name << ": float " << single_asymmetry << ", double on float " << double_asymmetry);
    CHECK(single_asymmetry < 1e-5);
    CHECK(double_asymmetry < 1e-12);
    CHECK(single_positivity > 0.0);
    CHECK(double_positivity > 0.0);
  }
}

TEST_CASE("ch12: the float numbers are chapter 10's rounded, and half their bytes", "[ch12]") {
  const Scene scene = test::test_scene("cantilever");
  ch10::MultigridStepper stepper(scene, {},
                                 ch10::multigrid_params<ch10::MultigridRecipe>(three_levels()));
  State state = rest_state(scene);
  stepper.step(state);
  ch12::ReducedVCycle<float> single(stepper.preconditioner().multigrid());
  ch12::ReducedVCycle<double> widened(stepper.preconditioner().multigrid());
  single.prepare(stepper.system_matrix());
  widened.prepare(stepper.system_matrix());
  CHECK(single.number_bytes() == widened.number_bytes());
  // Chapter 10's hierarchy in double: blocks, prolongators both ways, inverse diagonals.
  const ch10::Multigrid& mg = stepper.preconditioner().multigrid();
  long long double_bytes = 0;
  for (int l = 0; l < mg.levels() - 1; ++l) {
    const int b = l == 0 ? 3 : ch10::kModes;
    double_bytes += 8LL * b * b * ch10::level_blocks(mg, l);
    double_bytes += 8LL * b * b * (ch10::level_dofs(mg, l) / b);
    double_bytes += 2 * 8LL * b * ch10::kModes * ch10::prolongator_blocks(mg, l);
  }
  CHECK(2 * single.number_bytes() == double_bytes);
}

TEST_CASE("ch12: at most one iteration more than chapter 11 at 1e-4, and 1e-10 still reached",
          "[ch12]") {
  // The preconditioner only steers the search; PCG's residual and stopping rule are double.
  for (const double tolerance : {1e-4, 1e-10}) {
    for (const Scene& scene : test::equivalence_scenes()) {
      SolverSettings settings;
      settings.tolerance = tolerance;
      ch11::NodeOrderStepper reference(scene, settings);
      ch12::HalfBytesStepper single(scene, settings);
      ch08::StepOf<Widened> widened(scene, settings);
      State a = rest_state(scene), b = a, c = a;
      int worst = 0;
      for (int k = 0; k < 20; ++k) {
        reference.step(a);
        single.step(b);
        widened.step(c);
        REQUIRE(single.profile().converged);
        REQUIRE(widened.profile().converged);
        worst = std::max({worst, single.profile().cg_iterations - reference.profile().cg_iterations,
                          widened.profile().cg_iterations - reference.profile().cg_iterations});
      }
      INFO(scene.name << ", tolerance " << tolerance << ": most extra iterations " << worst);
      if (tolerance == 1e-4) CHECK(worst <= 1);
      CHECK((b.x - a.x).cwiseAbs().maxCoeff() < 1e3 * tolerance);
    }
  }
}

TEST_CASE("ch12: refuses chapter 10's Gauss-Seidel smoother", "[ch12]") {
  ch10::MultigridStepperSettings s;
  s.multigrid.relax.smoother = ch10::Smoother::GaussSeidel;
  CHECK_THROWS_AS(ch12::HalfBytesStepper(test::test_scene("cantilever"), {},
                                         ch10::multigrid_params<ch12::HalfTheBytes>(s)),
                  std::invalid_argument);
}

TEST_CASE("ch12: zero heap allocations per step after the first, with 2 threads", "[ch12]") {
  FEM_REQUIRE_ALLOCATION_COUNTER();
  const ThreadCountScope two(openmp_enabled() ? 2 : 1);
  for (const Scene& scene : test::equivalence_scenes()) {
    INFO(scene.name);
    CHECK(test::allocations_per_step("12", scene) == 0);
  }
}

namespace {

// A state of the test mesh, every node moved by a random rotation of the body plus noise,
// so that the elements turn and stretch; `invert` pushes node 0 of elements 3 and 9 through
// the opposite face and flattens element 12, so that their lanes take the SVD path while the
// other lanes of their batches converge by Newton.
State turned_state(const Scene& scene, std::mt19937& rng, bool invert) {
  std::normal_distribution<double> normal(0.0, 1.0);
  State s = rest_state(scene);
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(0.4, Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized())
          .toRotationMatrix();
  for (int i = 0; i < scene.mesh.num_nodes(); ++i) {
    s.x.segment<3>(3 * i) = R * s.x.segment<3>(3 * i);
    for (int k = 0; k < 3; ++k) s.x[3 * i + k] += 2e-3 * normal(rng);
    s.v.segment<3>(3 * i) = Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
  }
  if (!invert) return s;
  for (const int e : {3, 9, 12}) {
    const Eigen::Vector4i t = scene.mesh.tets[e];
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (int a = 1; a < 4; ++a) centroid += s.x.segment<3>(3 * t[a]) / 3.0;
    const double push = e == 12 ? 1.0 - 1e-9 : 2.0;  // 12: onto the face, nearly flat
    s.x.segment<3>(3 * t[0]) += push * (centroid - s.x.segment<3>(3 * t[0]));
  }
  return s;
}

// The largest difference between the batched terms and chapter 08's over all elements,
// relative to the largest entry, after `steps` passes over the states given (warm starts).
double batched_against_chapter_08(const Scene& scene, const std::vector<State>& states,
                                  long long& fallbacks_08, long long& fallbacks_12) {
  const Model model(scene);
  ch08::FusedElements reference(model, scene);
  ch12::BatchedElements batched(model, scene);
  const int n = static_cast<int>(model.tets.size());
  double worst = 0.0;
  for (const State& state : states) {
    fallbacks_08 = fallbacks_12 = 0;
    ch08::ElementTerms expected;
    ch12::BatchTerms terms;
    for (int first = 0; first < n; first += ch12::kLanes) {
      const int count = std::min(ch12::kLanes, n - first);
      batched.terms(first, count, model.tets, state, fallbacks_12, terms);
      for (int l = 0; l < count; ++l) {
        reference.terms(first + l, model.tets[first + l], state, fallbacks_08, expected);
        double scale = expected.rhs.cwiseAbs().maxCoeff(), error = 0.0;
        for (int i = 0; i < 3; ++i)
          for (int a = 0; a < 4; ++a)
            error = std::max(error, std::abs(terms.rhs[i][a].v[l] - expected.rhs(i, a)));
        worst = std::max(worst, error / scale);
        scale = 0.0;
        error = 0.0;
        for (int p = 0; p < 10; ++p)
          for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) {
              scale = std::max(scale, std::abs(expected.K[p](i, j)));
              error = std::max(error, std::abs(terms.K[p][i][j].v[l] - expected.K[p](i, j)));
            }
        worst = std::max(worst, error / scale);
        // The rotation each keeps for the next step (q and -q are the same rotation).
        const Eigen::Quaterniond q8 = reference.rotations()[first + l],
                                 q12 = batched.rotation(first + l);
        worst = std::max(worst, std::min((q8.coeffs() - q12.coeffs()).norm(),
                                         (q8.coeffs() + q12.coeffs()).norm()));
      }
    }
    reference.end_pass(fallbacks_08);
    batched.end_pass(fallbacks_12);
  }
  return worst;
}

}  // namespace

TEST_CASE("ch12: the batched element terms equal chapter 08's, element by element", "[ch12]") {
  // Three passes (the first cold, then warm starts extrapolated from the last two), on turned
  // and stretched elements: every lane converges by Newton, as chapter 08 does.
  const Scene scene = test::test_scene("cantilever");
  std::mt19937 rng(12);
  std::vector<State> states;
  for (int k = 0; k < 3; ++k) states.push_back(turned_state(scene, rng, false));
  long long f08 = 0, f12 = 0;
  const double worst = batched_against_chapter_08(scene, states, f08, f12);
  INFO("largest relative difference " << worst);
  CHECK(worst < 1e-10);
  CHECK(f12 == f08);
}

TEST_CASE("ch12: inverted and flat lanes take chapter 08's SVD path beside Newton's lanes",
          "[ch12]") {
  // Elements 3, 9 (inverted) and 12 (flat) sit in batches whose other lanes converge by
  // Newton: each lane keeps its own path, and the fallbacks are counted as chapter 08 counts.
  const Scene scene = test::test_scene("cantilever");
  std::mt19937 rng(7);
  const std::vector<State> states = {turned_state(scene, rng, true),
                                     turned_state(scene, rng, true)};
  long long f08 = 0, f12 = 0;
  const double worst = batched_against_chapter_08(scene, states, f08, f12);
  INFO("largest relative difference " << worst << ", fallbacks " << f08 << " / " << f12);
  CHECK(worst < 1e-10);
  CHECK(f08 >= 3);
  CHECK(f12 == f08);
}

TEST_CASE("ch12: a short batch leaves the elements past its count untouched", "[ch12]") {
  const Scene scene = test::test_scene("cantilever");
  const Model model(scene);
  ch12::BatchedElements batched(model, scene);
  std::mt19937 rng(3);
  const State state = turned_state(scene, rng, false);
  ch12::BatchTerms terms;
  long long fallbacks = 0;
  batched.terms(0, 5, model.tets, state, fallbacks, terms);  // elements 0..4 only
  CHECK(batched.rotation(4).w() != 1.0);                     // element 4 turned
  for (int e = 5; e < 2 * ch12::kLanes; ++e)
    CHECK(batched.rotation(e).w() == 1.0);  // still the rest
}
