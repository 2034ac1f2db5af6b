// Chapter 10: the multigrid preconditioner is what PCG's theory needs (symmetric, positive
// definite on the filtered space), its coarse matrices are the Galerkin products, it cuts the
// iterations, the state is the same to the last bit on 1 and 2 threads, and the stepper still
// matches chapter 01 without allocating.
#include "catch2_compat.hpp"
#include "chapters/09_threads/stepper.hpp"
#include "chapters/10_multigrid/stepper.hpp"
#include "common/threads.hpp"
#include "support.hpp"

using namespace fem;

namespace {

std::vector<Scene> all_scenes() { return test::equivalence_scenes(); }

Eigen::VectorXd filtered_random(const Scene& scene, Eigen::Index size) {
  Eigen::VectorXd v = Eigen::VectorXd::Random(size);
  for (const auto& c : scene.constraints) v.segment<3>(3 * c.node) = c.filter * v.segment<3>(3 * c.node);
  return v;
}

// The test mesh is small (190 nodes): a coarse limit below the default gives it the three
// levels a poster-sized mesh has, so that every code path of the V-cycle runs.
using Smoother = ch10::MultigridSettings::Smoother;
constexpr Smoother kSmoothers[] = {Smoother::GaussSeidel, Smoother::Jacobi};

ch10::MultigridSettings three_levels(Smoother smoother = Smoother::GaussSeidel) {
  ch10::MultigridSettings s;
  s.max_coarse_dofs = 24;
  s.smoother = smoother;
  return s;
}

}  // namespace

FEM_CHAPTER_TESTS("10", "[ch10]")

TEST_CASE("ch10: bit-identical states after 50 steps with 1 and 2 threads", "[ch10]") {
  // The V-cycle runs on one thread; everything around it is chapter 09's deterministic
  // parallel step, so the thread count must not change a bit.
  const auto run_with = [](const Scene& scene, int threads) {
    const ThreadCountScope scope(threads);
    ch10::MultigridStepper stepper(scene, {});
    State state = rest_state(scene);
    for (int k = 0; k < 50; ++k) stepper.step(state);
    return state;
  };
  for (const Scene& scene : {test::test_scene("cantilever"), test::driven_scene()}) {
    const State reference = run_with(scene, 1);
    REQUIRE((reference.x - rest_state(scene).x).cwiseAbs().maxCoeff() > 1e-3);  // it moves
    const State state = run_with(scene, openmp_enabled() ? 2 : 1);
    INFO(scene.name);
    CHECK((state.x.array() == reference.x.array()).all());
    CHECK((state.v.array() == reference.v.array()).all());
  }
}

TEST_CASE("ch10: the V-cycle is symmetric positive definite on the filtered space", "[ch10]") {
  for (const Scene& scene : all_scenes()) {
    for (const Smoother smoother : kSmoothers) {
      ch10::MultigridStepper stepper(scene, {}, three_levels(smoother));
      State state = rest_state(scene);
      for (int k = 0; k < 3; ++k) stepper.step(state);
      ch10::Multigrid& mg = stepper.multigrid();
      REQUIRE(mg.levels() == 3);
      std::srand(10);
      const Eigen::Index n = stepper.system_rhs().size();
      Eigen::VectorXd Mx(n), My(n);
      for (int trial = 0; trial < 5; ++trial) {
        const Eigen::VectorXd x = filtered_random(scene, n), y = filtered_random(scene, n);
        mg.apply(x, Mx);
        mg.apply(y, My);
        INFO(scene.name << ", trial " << trial << ": x^T M y " << x.dot(My) << ", y^T M x "
                        << y.dot(Mx));
        CHECK(std::abs(x.dot(My) - y.dot(Mx)) <= 1e-12 * std::sqrt(x.dot(Mx) * y.dot(My)));
        CHECK(x.dot(Mx) > 0.0);
        CHECK(y.dot(My) > 0.0);
      }
    }
  }
}

TEST_CASE("ch10: every coarse matrix equals P^T A P computed by Eigen", "[ch10]") {
  for (const Scene& scene : all_scenes()) {
    ch10::MultigridStepper stepper(scene, {}, three_levels());
    State state = rest_state(scene);
    for (int k = 0; k < 3; ++k) stepper.step(state);
    const ch10::Multigrid& mg = stepper.multigrid();
    REQUIRE(mg.levels() == 3);
    // The finest level is the stepper's filtered system itself.
    CHECK((mg.level_matrix(0) - stepper.system_matrix().to_sparse()).norm() == 0.0);
    for (int l = 0; l + 1 < mg.levels(); ++l) {
      const Eigen::SparseMatrix<double> P = mg.prolongator(l);
      const Eigen::SparseMatrix<double> A = mg.level_matrix(l);
      Eigen::SparseMatrix<double> expected = Eigen::SparseMatrix<double>(P.transpose()) * A * P;
      // Modes an aggregate lacks have zero rows and columns there, and the identity instead.
      const Eigen::VectorXd unused = mg.unused_modes(l + 1);
      for (Eigen::Index k = 0; k < unused.size(); ++k)
        if (unused[k] != 0.0) expected.coeffRef(k, k) += unused[k];
      const Eigen::SparseMatrix<double> coarse = mg.level_matrix(l + 1);
      INFO(scene.name << ", level " << l + 1 << ": " << coarse.rows() << " unknowns");
      CHECK(coarse.rows() == P.cols());
      CHECK((coarse - expected).norm() <= 1e-12 * expected.norm());
    }
  }
}

TEST_CASE("ch10: a mode is unused exactly where its prolongator column is zero", "[ch10]") {
  for (const int modes : {6, 3}) {
    for (const Scene& scene : all_scenes()) {
      ch10::MultigridSettings settings = three_levels();
      settings.modes = modes;
      ch10::MultigridStepper stepper(scene, {}, settings);
      State state = rest_state(scene);
      stepper.step(state);
      CHECK(stepper.profile().converged);
      const ch10::Multigrid& mg = stepper.multigrid();
      for (int l = 0; l + 1 < mg.levels(); ++l) {
        const Eigen::SparseMatrix<double> P = mg.prolongator(l);
        const Eigen::VectorXd unused = mg.unused_modes(l + 1);
        int zero_columns = 0;
        for (Eigen::Index k = 0; k < P.cols(); ++k) {
          const bool zero = P.col(k).norm() == 0.0;
          zero_columns += zero;
          CHECK(zero == (unused[k] == 1.0));
        }
        INFO(scene.name << ", " << modes << " modes, level " << l + 1);
        // Three modes only: the rotations' columns of every aggregate are unused.
        if (modes == 3) CHECK(2 * zero_columns >= P.cols());
      }
    }
  }
}

TEST_CASE("ch10: iterations on the test mesh at most 8, a sixth of the block-Jacobi PCG's",
          "[ch10]") {
  // Both at the default tolerance 1e-4 from the same states, side by side for 20 steps.
  for (const Scene& scene : all_scenes()) {
    ch09::ThreadsStepper jacobi(scene, {});
    ch10::MultigridStepper multigrid(scene, {});
    State a = rest_state(scene), b = rest_state(scene);
    int most = 0, most_jacobi = 0;
    for (int k = 0; k < 20; ++k) {
      jacobi.step(a);
      multigrid.step(b);
      most = std::max(most, multigrid.profile().cg_iterations);
      most_jacobi = std::max(most_jacobi, jacobi.profile().cg_iterations);
      CHECK(multigrid.profile().converged);
    }
    INFO(scene.name << ": at most " << most << " iterations, block Jacobi " << most_jacobi);
    CHECK(most <= 8);
    CHECK(6 * most <= most_jacobi);
  }
}

TEST_CASE("ch10: zero heap allocations per step after the first, with 2 threads",
          "[ch10][alloc]") {
  FEM_REQUIRE_ALLOCATION_COUNTER();
  // OpenMP's team is set up in the first step (as in the threaded chapter before).
  const ThreadCountScope threads(openmp_enabled() ? 2 : 1);
  for (const Scene& scene : all_scenes()) {
    INFO(scene.name);
    CHECK(test::allocations_per_step("10", scene) == 0);
    // The three-level hierarchy too, with either smoother.
    for (const Smoother smoother : kSmoothers) {
      ch10::MultigridStepper stepper(scene, {}, three_levels(smoother));
      State state = rest_state(scene);
      stepper.step(state);
      alloc::Scope scope;
      for (int k = 0; k < 5; ++k) stepper.step(state);
      CHECK(scope.allocations() == 0);
    }
  }
}

TEST_CASE("ch10: set-up refuses a matrix of another pattern and bad settings", "[ch10]") {
  const Scene scene = test::test_scene("cantilever");
  ch10::MultigridStepper stepper(scene, {});
  const std::vector<Eigen::Matrix3d> wrong(3, Eigen::Matrix3d::Identity());
  CHECK_THROWS_AS(stepper.multigrid().prepare(wrong), std::invalid_argument);
  ch10::MultigridSettings bad;
  bad.modes = 4;
  CHECK_THROWS_AS(ch10::MultigridStepper(scene, {}, bad), std::invalid_argument);
}

TEST_CASE("ch10: coarse matrices kept for several steps give the same motion", "[ch10]") {
  // A lagged V-cycle is still SPD, so PCG reaches the same tolerance: only iterations change.
  const Scene scene = test::driven_scene();
  ch10::MultigridSettings lagged = three_levels();
  lagged.coarse_refresh = 3;
  ch10::MultigridStepper every_step(scene, test::tight_solver(), three_levels());
  ch10::MultigridStepper every_third(scene, test::tight_solver(), lagged);
  State a = rest_state(scene), b = rest_state(scene);
  const Eigen::VectorXd X = a.x;
  double motion = 0.0, difference = 0.0;
  for (int k = 0; k < 20; ++k) {
    every_step.step(a);
    every_third.step(b);
    CHECK(every_third.profile().converged);
    motion = std::max(motion, (a.x - X).cwiseAbs().maxCoeff());
    difference = std::max(difference, (a.x - b.x).cwiseAbs().maxCoeff());
  }
  INFO("max |dx| " << difference << " of motion " << motion);
  CHECK(difference < 1e-8 * motion);
  // The last step (the 20th) kept the coarse matrices of the 19th: still SPD.
  std::srand(11);
  const Eigen::Index n = X.size();
  const Eigen::VectorXd x = filtered_random(scene, n), y = filtered_random(scene, n);
  Eigen::VectorXd Mx(n), My(n);
  every_third.multigrid().apply(x, Mx);
  every_third.multigrid().apply(y, My);
  CHECK(std::abs(x.dot(My) - y.dot(Mx)) <= 1e-12 * std::sqrt(x.dot(Mx) * y.dot(My)));
  CHECK(x.dot(Mx) > 0.0);
}
