// Chapter 10: the multigrid preconditioner is what PCG's theory needs (symmetric, positive
// definite on the filtered space, also on lagged coarse levels), its coarse matrices are the
// Galerkin products right after a refresh, it cuts the iterations, the state is the same to
// the last bit on 1, 2 and 3 threads with every smoother, the stepper still matches chapter 01
// without allocating, and a long run under a jumping mouse spring stays bounded while the
// jumps trigger refreshes.
#include <random>

#include "catch2_compat.hpp"
#include "chapters/09_threads/stepper.hpp"
#include "chapters/10_multigrid/report.hpp"
#include "chapters/10_multigrid/stepper.hpp"
#include "common/threads.hpp"
#include "support.hpp"

using namespace fem;

namespace {

std::vector<Scene> all_scenes() { return test::equivalence_scenes(); }

Eigen::VectorXd filtered_random(const Scene& scene, Eigen::Index size) {
  Eigen::VectorXd v = Eigen::VectorXd::Random(size);
  for (const auto& c : scene.constraints)
    v.segment<3>(3 * c.node) = c.filter * v.segment<3>(3 * c.node);
  return v;
}

// The test mesh is small (190 nodes): a coarse limit below the default gives it the three
// levels a poster-sized mesh has, so that every code path of the V-cycle runs.
// Small row blocks (block_rows 4) give every level several blocks, so that the threads share
// out the coarse levels too.
using Smoother = ch10::Smoother;
constexpr Smoother kSmoothers[] = {Smoother::Chebyshev, Smoother::GaussSeidel, Smoother::Jacobi};

ch10::MultigridStepperSettings three_levels(Smoother smoother = ch10::SmootherSettings{}.smoother) {
  ch10::MultigridStepperSettings s;
  s.multigrid.max_coarse_dofs = 24;
  s.multigrid.relax.smoother = smoother;
  s.multigrid.rows.block_rows = 4;
  return s;
}

// 1, 2 and 3 threads with OpenMP (3: a count that divides nothing evenly); 1 without.
std::vector<int> thread_counts() {
  return openmp_enabled() ? std::vector<int>{1, 2, 3} : std::vector<int>{1};
}

bool bit_identical(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return a.size() == b.size() && (a.array() == b.array()).all();
}

}  // namespace

FEM_CHAPTER_TESTS("10", "[ch10]")

TEST_CASE("ch10: bit-identical states after 50 steps with 1, 2 and 3 threads", "[ch10]") {
  // Every loop of prepare and of the V-cycle goes over fixed row blocks, every sum in a fixed
  // order, and the refresh rule reads only iteration counts: the thread count must not change
  // a bit, with the default settings and with every smoother on three levels of small blocks.
  const auto run_with = [](const Scene& scene, int threads,
                           const ch10::MultigridStepperSettings& s) {
    const ThreadCountScope scope(threads);
    ch10::MultigridStepper stepper(scene, {}, ch10::multigrid_params<ch10::MultigridRecipe>(s));
    stepper.team().adaptive_team().set_enabled(false);  // really this many threads, every step
    State state = rest_state(scene);
    for (int k = 0; k < 50; ++k) stepper.step(state);
    return state;
  };
  std::vector<ch10::MultigridStepperSettings> settings = {ch10::MultigridStepperSettings{}};
  for (const Smoother smoother : kSmoothers) settings.push_back(three_levels(smoother));
  for (const Scene& scene : {test::test_scene("cantilever"), test::driven_scene()})
    for (const auto& s : settings) {
      const State reference = run_with(scene, 1, s);
      REQUIRE((reference.x - rest_state(scene).x).cwiseAbs().maxCoeff() > 1e-3);  // it moves
      for (const int threads : thread_counts()) {
        const State state = run_with(scene, threads, s);
        INFO(scene.name << ", smoother " << static_cast<int>(s.multigrid.relax.smoother) << ", "
                        << threads << " threads");
        CHECK(bit_identical(state.x, reference.x));
        CHECK(bit_identical(state.v, reference.v));
      }
    }
}

TEST_CASE("ch10: the V-cycle is symmetric positive definite on the filtered space", "[ch10]") {
  for (const Scene& scene : all_scenes()) {
    for (const Smoother smoother : kSmoothers) {
      ch10::MultigridStepper stepper(
          scene, {}, ch10::multigrid_params<ch10::MultigridRecipe>(three_levels(smoother)));
      State state = rest_state(scene);
      for (int k = 0; k < 3; ++k) stepper.step(state);
      ch10::Multigrid& mg = stepper.preconditioner().multigrid();
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

TEST_CASE("ch10: every coarse matrix equals P^T A P computed by Eigen after a refresh", "[ch10]") {
  // The default refresh rule keeps the coarse matrices for several steps: step until a refresh
  // past the first one (the prolongator is smoothed on the first), then compare.
  for (const Scene& scene : all_scenes()) {
    ch10::MultigridStepper stepper(scene, {},
                                   ch10::multigrid_params<ch10::MultigridRecipe>(three_levels()));
    State state = rest_state(scene);
    stepper.step(state);
    int steps = 1;
    do {
      stepper.step(state);
      ++steps;
    } while (!stepper.preconditioner().multigrid().refresh_rule().refreshed() && steps < 100);
    const ch10::Multigrid& mg = stepper.preconditioner().multigrid();
    REQUIRE(mg.refresh_rule().refreshed());
    REQUIRE(mg.levels() == 3);
    // The finest level is the stepper's filtered system itself.
    CHECK((ch10::level_matrix(mg, 0) - stepper.system_matrix().to_sparse()).norm() == 0.0);
    for (int l = 0; l + 1 < mg.levels(); ++l) {
      const Eigen::SparseMatrix<double> P = ch10::prolongator(mg, l);
      const Eigen::SparseMatrix<double> A = ch10::level_matrix(mg, l);
      Eigen::SparseMatrix<double> expected = Eigen::SparseMatrix<double>(P.transpose()) * A * P;
      // Modes an aggregate lacks have zero rows and columns there, and the identity instead.
      const Eigen::VectorXd unused = ch10::missing_modes(mg, l + 1);
      for (Eigen::Index k = 0; k < unused.size(); ++k)
        if (unused[k] != 0.0) expected.coeffRef(k, k) += unused[k];
      const Eigen::SparseMatrix<double> coarse = ch10::level_matrix(mg, l + 1);
      INFO(scene.name << ", level " << l + 1 << ": " << coarse.rows() << " unknowns");
      CHECK(coarse.rows() == P.cols());
      CHECK((coarse - expected).norm() <= 1e-12 * expected.norm());
    }
  }
}

TEST_CASE("ch10: a mode is unused exactly where its prolongator column is zero", "[ch10]") {
  for (const int modes : {6, 3}) {
    for (const Scene& scene : all_scenes()) {
      ch10::MultigridStepperSettings settings = three_levels();
      settings.multigrid.coarsening.modes = modes;
      ch10::MultigridStepper stepper(scene, {},
                                     ch10::multigrid_params<ch10::MultigridRecipe>(settings));
      State state = rest_state(scene);
      stepper.step(state);
      CHECK(stepper.profile().converged);
      const ch10::Multigrid& mg = stepper.preconditioner().multigrid();
      for (int l = 0; l + 1 < mg.levels(); ++l) {
        const Eigen::SparseMatrix<double> P = ch10::prolongator(mg, l);
        const Eigen::VectorXd unused = ch10::missing_modes(mg, l + 1);
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

TEST_CASE("ch10: zero heap allocations per step after the first, with 2 threads", "[ch10][alloc]") {
  FEM_REQUIRE_ALLOCATION_COUNTER();
  // OpenMP's team is set up in the first step (as in the threaded chapter before).
  const ThreadCountScope threads(openmp_enabled() ? 2 : 1);
  for (const Scene& scene : all_scenes()) {
    INFO(scene.name);
    CHECK(test::allocations_per_step("10", scene) == 0);
    // The three-level hierarchy too, with either smoother.
    for (const Smoother smoother : kSmoothers) {
      ch10::MultigridStepper stepper(
          scene, {}, ch10::multigrid_params<ch10::MultigridRecipe>(three_levels(smoother)));
      State state = rest_state(scene);
      stepper.step(state);
      alloc::Scope scope;
      for (int k = 0; k < 5; ++k) stepper.step(state);
      CHECK(scope.allocations() == 0);
    }
  }
}

TEST_CASE("ch10: serial_rows runs the small levels on one thread, to the same bits", "[ch10]") {
  // A level with fewer rows than serial_rows, and every level below it, runs on one thread
  // (for_levels_from and v_cycle): the same sums in the same order, so the same state.
  const Scene scene = test::test_scene("cantilever");
  const ThreadCountScope threads(openmp_enabled() ? 2 : 1);
  const auto run = [&](int serial_rows, State& state) {
    ch10::MultigridStepperSettings s = three_levels();
    s.multigrid.rows.serial_rows = serial_rows;
    ch10::MultigridStepper stepper(scene, {}, ch10::multigrid_params<ch10::MultigridRecipe>(s));
    stepper.team().adaptive_team().set_enabled(false);
    state = rest_state(scene);
    for (int k = 0; k < 20; ++k) stepper.step(state);
    std::vector<bool> serial = {stepper.preconditioner().multigrid().fine_level().rows.serial};
    for (const auto& level : stepper.preconditioner().multigrid().coarse_levels())
      serial.push_back(level.rows.serial);
    return serial;
  };
  const int fine_rows = scene.mesh.num_nodes();
  State shared, coarse_serial;
  const std::vector<bool> none = run(0, shared);
  const std::vector<bool> coarse_only = run(fine_rows, coarse_serial);  // all rows but the fine
  REQUIRE(none.size() == 3);
  CHECK(none == std::vector<bool>{false, false, false});
  CHECK(coarse_only == std::vector<bool>{false, true, true});
  CHECK(bit_identical(shared.x, coarse_serial.x));
  CHECK(bit_identical(shared.v, coarse_serial.v));
}

TEST_CASE("ch10: set-up refuses a matrix of another pattern and bad settings", "[ch10]") {
  const Scene scene = test::test_scene("cantilever");
  ch10::MultigridStepper stepper(scene, {});
  const std::vector<Eigen::Matrix3d> wrong(3, Eigen::Matrix3d::Identity());
  CHECK_THROWS_AS(stepper.preconditioner().multigrid().factorize(wrong), std::invalid_argument);
  ch10::MultigridStepperSettings bad;
  bad.multigrid.coarsening.modes = 4;
  CHECK_THROWS_AS(
      ch10::MultigridStepper(scene, {}, ch10::multigrid_params<ch10::MultigridRecipe>(bad)),
      std::invalid_argument);
}

TEST_CASE("ch10: lagged coarse matrices give the same motion and an SPD V-cycle", "[ch10]") {
  // A lagged V-cycle is still SPD, so PCG reaches the same tolerance: only iterations change.
  const Scene scene = test::driven_scene();
  ch10::MultigridStepperSettings every_step = three_levels(), lagged = three_levels();
  every_step.multigrid.refresh.every = 1;
  lagged.multigrid.refresh.every = 5;  // every fifth step only: the rule without its early refresh
  lagged.multigrid.refresh.growth = 0.0;
  ch10::MultigridStepper fresh(scene, test::tight_solver(),
                               ch10::multigrid_params<ch10::MultigridRecipe>(every_step));
  ch10::MultigridStepper stale(scene, test::tight_solver(),
                               ch10::multigrid_params<ch10::MultigridRecipe>(lagged));
  State a = rest_state(scene), b = rest_state(scene);
  const Eigen::VectorXd X = a.x;
  double motion = 0.0, difference = 0.0;
  for (int k = 0; k < 20; ++k) {
    const Eigen::SparseMatrix<double> coarse =
        ch10::level_matrix(stale.preconditioner().multigrid(), 1);
    fresh.step(a);
    stale.step(b);
    CHECK(stale.profile().converged);
    // Between refreshes the coarse matrices are the old ones, to the bit.
    if (k > 0 && !stale.preconditioner().multigrid().refresh_rule().refreshed())
      CHECK((ch10::level_matrix(stale.preconditioner().multigrid(), 1) - coarse).norm() == 0.0);
    motion = std::max(motion, (a.x - X).cwiseAbs().maxCoeff());
    difference = std::max(difference, (a.x - b.x).cwiseAbs().maxCoeff());
  }
  CHECK(fresh.preconditioner().multigrid().refresh_rule().refreshes() == 20);
  CHECK(stale.preconditioner().multigrid().refresh_rule().refreshes() ==
        4);  // steps 1, 6, 11 and 16
  INFO("max |dx| " << difference << " of motion " << motion);
  CHECK(difference < 1e-8 * motion);
  // The last step (the 20th) kept the coarse matrices of the 16th: still SPD.
  for (const Smoother smoother : kSmoothers) {
    lagged.multigrid.relax.smoother = smoother;
    ch10::MultigridStepper stepper(scene, {},
                                   ch10::multigrid_params<ch10::MultigridRecipe>(lagged));
    State state = rest_state(scene);
    for (int k = 0; k < 8; ++k) stepper.step(state);
    REQUIRE(!stepper.preconditioner().multigrid().refresh_rule().refreshed());
    std::srand(11);
    const Eigen::Index n = X.size();
    const Eigen::VectorXd x = filtered_random(scene, n), y = filtered_random(scene, n);
    Eigen::VectorXd Mx(n), My(n);
    stepper.preconditioner().multigrid().apply(x, Mx);
    stepper.preconditioner().multigrid().apply(y, My);
    INFO("smoother " << static_cast<int>(smoother));
    CHECK(std::abs(x.dot(My) - y.dot(Mx)) <= 1e-12 * std::sqrt(x.dot(Mx) * y.dot(My)));
    CHECK(x.dot(Mx) > 0.0);
    CHECK(y.dot(My) > 0.0);
  }
}

namespace {

struct Soak {
  State state;
  int most_iterations = 0, not_converged = 0;
  long long refreshes = 0, jump_refreshes = 0;
  std::string diverged;
};

// A few thousand steps under the jumping mouse spring (support.hpp), a new node every 50 steps
// (chapter 09's soak holds 7: longer holds, so that the lag's steady state shows between jumps).
// Counts the refreshes in the 3 steps after each jump.
Soak soak(const Scene& scene, int threads, int steps) {
  const ThreadCountScope scope(threads);
  ch10::MultigridStepper stepper(scene, {});
  stepper.team().adaptive_team().set_enabled(false);
  test::JumpingMouse mouse(scene, 50);
  Soak out;
  out.state = rest_state(scene);
  out.diverged = test::soak_under_mouse(stepper, mouse, out.state, steps, [&](int k) {
    out.not_converged += stepper.profile().converged ? 0 : 1;
    out.most_iterations = std::max(out.most_iterations, stepper.profile().cg_iterations);
    if (mouse.just_jumped(k, 3) && stepper.preconditioner().multigrid().refresh_rule().refreshed())
      ++out.jump_refreshes;
  });
  out.refreshes = stepper.preconditioner().multigrid().refresh_rule().refreshes();
  return out;
}

}  // namespace

TEST_CASE("ch10: soak, thousands of steps under a jumping mouse spring, 1 and 2 threads",
          "[ch10][soak]") {
  const Scene scene = test::test_scene("cantilever");
  const int steps = test::soak_steps(3000);
  std::vector<Soak> runs;
  for (const int threads : openmp_enabled() ? std::vector<int>{1, 2} : std::vector<int>{1}) {
    runs.push_back(soak(scene, threads, steps));
    const Soak& r = runs.back();
    INFO(threads << " threads: at most " << r.most_iterations << " iterations, " << r.refreshes
                 << " refreshes, " << r.jump_refreshes << " right after a jump");
    CHECK(r.diverged.empty());
    CHECK(r.not_converged == 0);
    CHECK(r.most_iterations <= 16);
    // The rule refreshes every k-th step and when the iterations grow: the jumps trigger
    // refreshes beyond the periodic ones, most of them within 3 steps of the jump.
    const int k = ch10::RefreshSettings{}.every;
    CHECK(r.refreshes > steps / k);
    CHECK(r.jump_refreshes > steps / 50 / 2);
  }
  if (runs.size() == 2) {
    CHECK(bit_identical(runs[0].state.x, runs[1].state.x));
    CHECK(bit_identical(runs[0].state.v, runs[1].state.v));
  }
}

// A body that lands flat on a floor: the plate's 964 bottom nodes get their Plane constraints
// in place after a step without them. The hierarchy was set up on that first matrix; kept as it
// was, chapter 11 took about 350 iterations a solve and chapters 12-14 hit the cap (2000) with a
// relative residual of 0.1. Set up again (Multigrid::set_constraints), every multigrid chapter
// solves in at most two iterations more than a stepper built with those constraints, from the
// same state, and converges.
TEST_CASE("ch10: constraints set in place after a step set the multigrid up again, 10 to 14",
          "[ch10]") {
  Scene free = make_scene("cantilever", load_mesh(test::mesh_path("plate_poster.msh")));
  free.constraints.clear();
  const double floor = free.mesh.X.row(2).minCoeff();
  std::vector<NodeConstraint> on_floor;
  for (int n = 0; n < free.mesh.num_nodes(); ++n)
    if (free.mesh.X(2, n) == floor)
      on_floor.push_back(NodeConstraint::plane(n, Eigen::Vector3d::UnitZ()));
  REQUIRE(on_floor.size() == 964);
  Scene held = free;
  held.constraints = on_floor;
  for (const std::string chapter : {"10", "11", "12", "13", "14"}) {
    INFO("chapter " << chapter);
    const auto in_place = make_stepper(chapter, free, {});
    State landed = rest_state(free);
    in_place->step(landed);  // falls freely
    in_place->set_constraints(on_floor);
    for (const NodeConstraint& c : on_floor) {  // put on the floor, as the library's floor does
      landed.x[3 * c.node + 2] = floor;
      landed.v[3 * c.node + 2] = 0.0;
    }
    const auto built = make_stepper(chapter, held, {});
    State a = landed, b = landed;
    for (int k = 0; k < 5; ++k) {
      in_place->step(a);
      built->step(b);
      INFO("step " << k << ": " << in_place->profile().cg_iterations << " iterations in place, "
                   << built->profile().cg_iterations << " built with the constraints");
      CHECK(in_place->profile().converged);
      CHECK(in_place->profile().cg_iterations <= built->profile().cg_iterations + 2);
    }
  }
}
