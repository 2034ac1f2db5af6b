// Chapter 10's lesson table: `fem_lessons multigrid`, the measurements behind the lesson on
// one scene.
//  - runs chapter 10 for some steps with the multigrid settings given (modes, smoother,
//    sweeps, prolongator) and reports median PCG iterations and solve time per step;
//  - on the last step's filtered system: the hierarchy (levels, unknowns, blocks), the cost
//    of prepare() and of one V-cycle in SpMV-equivalents, and PCG from a zero guess with the
//    V-cycle, with chapter 09's block Jacobi and with Eigen's IncompleteCholesky CG;
//  - with --export DIR: that system as Matrix Market (A.mtx, b.mtx, the filtered rigid-body
//    modes B.mtx) and summary.json, for fem-tools runs pyamg.
// The report goes to stderr, the table (for --readme) to stdout.
#include "chapters/10_multigrid/lesson.hpp"

#include <Eigen/IterativeLinearSolvers>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <string>
#include <unsupported/Eigen/SparseExtra>
#include <vector>

#include "chapters/09_threads/parallel.hpp"
#include "chapters/09_threads/parallel_pcg.hpp"
#include "chapters/10_multigrid/lesson_options.hpp"
#include "chapters/10_multigrid/report.hpp"
#include "chapters/10_multigrid/stepper.hpp"
#include "common/json.hpp"
#include "common/threads.hpp"

namespace fem::ch10 {

namespace {

using Clock = std::chrono::steady_clock;

// The filtered rigid-body modes of the whole body, 3N x 6: PyAMG's B (rigid_body_modes in
// near_null_space.hpp gives each aggregate's, about its own centroid).
Eigen::MatrixXd whole_body_modes(const Scene& scene) {
  const int n = scene.mesh.num_nodes();
  Eigen::MatrixXd B = Eigen::MatrixXd::Zero(3 * n, 6);
  const Eigen::Vector3d c = scene.mesh.X.rowwise().mean();
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d r = scene.mesh.X.col(i) - c;
    B.block<3, 3>(3 * i, 0).setIdentity();
    B.block<3, 3>(3 * i, 3) << 0.0, r.z(), -r.y(), -r.z(), 0.0, r.x(), r.y(), -r.x(), 0.0;
  }
  for (const auto& k : scene.constraints)
    B.middleRows<3>(3 * k.node) = k.filter * B.middleRows<3>(3 * k.node);
  return B;
}

// Chapter 10 over the run's steps, as fem_bench runs it (warm start, the refresh rule).
struct RunStats {
  std::vector<double> iterations, solve_ms, step_ms;
  double setup_ms = 0.0;
  long long refreshes = 0;
};

RunStats run_chapter(MultigridStepper& stepper, const Scene& scene, int steps) {
  RunStats out;
  State state = rest_state(scene);
  for (int k = 0; k < steps; ++k) {
    stepper.step(state);
    const StepProfile& p = stepper.profile();
    if (const char* why = divergence(state, p))
      throw std::runtime_error("diverged at step " + std::to_string(k + 1) + ": " + why);
    out.iterations.push_back(p.cg_iterations);
    out.solve_ms.push_back(1e3 * p.solve.seconds);
    out.step_ms.push_back(1e3 * p.step.seconds);
    if ((k + 1) % std::max(1, steps / 4) == 0)
      std::cerr << "  step " << k + 1 << "/" << steps << "\n" << std::flush;
  }
  out.refreshes = stepper.preconditioner().multigrid().refresh_rule().refreshes();
  return out;
}

// Milliseconds per call of f inside one parallel region of the current thread count (as the
// PCG calls the V-cycle: the region's opening is not part of it), median of 5 regions.
template <class F>
double team_ms(int calls, F&& f) {
  const double budget_s = 2.0;  // a busy machine makes a barrier cost milliseconds
  return time_ms(
             5,
             [&] {
               ch09::run_parallel([&] {
                 for (int k = 0; k < calls; ++k) f();
               });
             },
             budget_s) /
         calls;
}

// The costs of one level at one thread count, in ms.
struct LevelCost {
  double between = 0.0, refresh = 0.0, cycle_from = 0.0;
};

struct Costs {
  int threads = 1;
  std::vector<LevelCost> level;
  double v_cycle = 0.0, prepare_per_step = 0.0;
};

// prepare's own work per level (between refreshes and at one), the V-cycle from each level
// down (a level's share is the difference), the whole V-cycle, and prepare per step averaged
// over a run with `refreshes` refreshes in `steps` steps.
Costs measure_costs(Multigrid& mg, const Eigen::VectorXd& b, int threads, long long refreshes,
                    int steps) {
  const ThreadCountScope scope(threads);
  Costs c;
  c.threads = threads;
  Eigen::VectorXd y(b.size());
  for (int l = 0; l < mg.levels(); ++l) {
    LevelCost cost;  // between refreshes prepare() touches the finest level only
    if (l == 0) cost.between = team_ms(5, [&] { mg.factorize_level(l, false); });
    cost.refresh = team_ms(5, [&] { mg.factorize_level(l, true); });
    cost.cycle_from = team_ms(20, [&] { mg.cycle_from(l); });
    c.level.push_back(cost);
  }
  c.v_cycle = team_ms(20, [&] { mg.apply(b, y); });
  double refresh = 0.0;
  for (const LevelCost& cost : c.level) refresh += cost.refresh;
  c.prepare_per_step =
      c.level[0].between + (refresh - c.level[0].between) * static_cast<double>(refreshes) / steps;
  return c;
}

std::string ms_spmv(double ms, double spmv) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(3) << ms << " (" << std::setprecision(1) << ms / spmv << ")";
  return s.str();
}

// The cost table: a column per thread count, SpMV-equivalents of the 1-thread SpMV.
std::string cost_table(const Multigrid& mg, const std::vector<Costs>& costs, double spmv,
                       const RunStats& run, int steps) {
  std::ostringstream t;
  t << "| ms (SpMV-equivalents) |";
  for (const Costs& c : costs) t << " " << c.threads << " thread(s) |";
  t << "\n| --- |" << std::string(3 * costs.size(), ' ');
  for (std::size_t k = 0; k < costs.size(); ++k) t << " ---: |";
  t << "\n";
  const auto row = [&](const std::string& name, auto&& value) {
    t << "| " << name << " |";
    for (const Costs& c : costs) t << " " << value(c) << " |";
    t << "\n";
  };
  for (int l = 0; l < mg.levels(); ++l) {
    const std::string level = "level " + std::to_string(l) + " (" +
                              std::to_string(level_row_blocks(mg, l)) + " row blocks): ";
    if (l == 0)
      row(level + "`prepare` between refreshes",
          [&](const Costs& c) { return ms_spmv(c.level[l].between, spmv); });
    row(level + "`prepare` at a refresh",
        [&](const Costs& c) { return ms_spmv(c.level[l].refresh, spmv); });
    row(level + "its share of one V-cycle", [&](const Costs& c) {
      const double below = l + 1 < mg.levels() ? c.level[l + 1].cycle_from : 0.0;
      return ms_spmv(c.level[l].cycle_from - below, spmv);
    });
  }
  row("`prepare` per step, averaged over the run (" + std::to_string(run.refreshes) +
          " refreshes in " + std::to_string(steps) + " steps)",
      [&](const Costs& c) { return ms_spmv(c.prepare_per_step, spmv); });
  row("one V-cycle", [&](const Costs& c) { return ms_spmv(c.v_cycle, spmv); });
  row("one V-cycle against 1 thread", [&](const Costs& c) {
    std::ostringstream s;
    s << std::fixed << std::setprecision(2) << "x" << c.v_cycle / costs.front().v_cycle;
    return s.str();
  });
  return t.str();
}

// PCG from zero on the last system: the V-cycle, block Jacobi, Eigen's IncompleteCholesky.
struct FromZero {
  SolveStats v_cycle, jacobi;
  double v_cycle_ms = 0.0, jacobi_ms = 0.0, ic_ms = 0.0;
  int ic_iterations = 0;
};

FromZero from_zero(MultigridStepper& stepper, const Scene& scene, const SolverSettings& solver) {
  const ch07::BlockSparseMatrix& A = stepper.system_matrix();
  const Eigen::VectorXd& b = stepper.system_rhs();
  FromZero out;
  ch09::ParallelPcg pcg(A, scene.constraints);
  const ch08::PartSetup setup{stepper.scene(), stepper.model(), stepper.system(),
                              stepper.settings()};
  ch08::AssembledProduct product(setup, {});
  const auto solve = [&](ch08::PreconditionerPart& M, SolveStats& stats, double& ms) {
    Eigen::VectorXd y = Eigen::VectorXd::Zero(b.size());
    stats = pcg.solve(A, product, M, b, solver, y);
    ms = time_ms(5, [&] {
      y.setZero();
      pcg.solve(A, product, M, b, solver, y);
    });
  };
  solve(stepper.preconditioner(), out.v_cycle, out.v_cycle_ms);
  ch09::JacobiOnChunks block_jacobi(setup, {});
  solve(block_jacobi, out.jacobi, out.jacobi_ms);
  const Eigen::SparseMatrix<double> csc = A.to_sparse();
  Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper,
                           Eigen::IncompleteCholesky<double>>
      ic;
  ic.setTolerance(solver.tolerance);
  ic.setMaxIterations(solver.max_iterations);
  Eigen::VectorXd yic;
  out.ic_ms = time_ms(3, [&] {
    ic.compute(csc);
    yic = ic.solve(b);
  });
  out.ic_iterations = static_cast<int>(ic.iterations());
  return out;
}

// The last system as Matrix Market for fem-tools runs pyamg, and a summary.
void export_system(const LessonRun& run, const MultigridStepper& stepper, const FromZero& z,
                   const std::string& dir) {
  const Scene& scene = run.scene;
  const Eigen::SparseMatrix<double> csc = stepper.system_matrix().to_sparse();
  const Eigen::VectorXd& b = stepper.system_rhs();
  std::filesystem::create_directories(dir);
  if (!Eigen::saveMarket(csc, dir + "/A.mtx") || !Eigen::saveMarketVector(b, dir + "/b.mtx") ||
      !Eigen::saveMarket(Eigen::SparseMatrix<double>(whole_body_modes(scene).sparseView()),
                         dir + "/B.mtx"))
    throw std::runtime_error("cannot write Matrix Market files into '" + dir + "'");
  Json summary;
  summary["mesh"] = mesh_name(scene);
  summary["scene"] = scene.name;
  summary["nodes"] = scene.mesh.num_nodes();
  summary["tolerance"] = solver_from_args(run.args).tolerance;
  summary["ours_iterations"] = z.v_cycle.iterations;
  summary["block_jacobi_iterations"] = z.jacobi.iterations;
  summary["ours_levels"] = stepper.preconditioner().multigrid().levels();
  write_json_file(dir + "/summary.json", summary);
  std::cerr << "wrote " << dir << "/{A,b,B}.mtx and summary.json\n";
}

void print_hierarchy(const Multigrid& mg, double setup_ms) {
  std::cerr << "\nhierarchy (set-up " << std::fixed << std::setprecision(1) << setup_ms
            << " ms for the whole stepper)\n";
  long long blocks = 0, fine_blocks = 0;
  for (int l = 0; l < mg.levels(); ++l) {
    const int block = l == 0 ? 3 : kModes;  // a node's 3 dofs, then an aggregate's modes
    std::cerr << "  level " << l << ": " << std::setw(7) << level_dofs(mg, l) << " unknowns, "
              << std::setw(8) << level_blocks(mg, l) << " blocks of " << block << "x" << block
              << ", " << level_row_blocks(mg, l) << " row blocks";
    if (l + 1 < mg.levels())
      std::cerr << ", P " << std::setw(7) << prolongator_blocks(mg, l) << " blocks of " << block
                << "x6";
    std::cerr << "\n";
    blocks += level_blocks(mg, l) * block * block;
    if (l == 0) fine_blocks = blocks;
  }
  std::cerr << "  operator complexity (stored entries, all levels / finest): "
            << std::setprecision(2) << static_cast<double>(blocks) / fine_blocks << "\n";
}

std::string main_table(const LessonRun& run, const Multigrid& mg, const RunStats& stats,
                       const FromZero& z, const std::vector<Costs>& costs, double spmv) {
  std::ostringstream t;
  t << std::fixed << std::setprecision(1);
  t << "| `" << mesh_name(run.scene) << "`, " << run.scene.name << ", " << run.steps << " steps, "
    << max_threads() << " thread(s) | value |\n"
    << "| --- | ---: |\n";
  for (int l = 0; l < mg.levels(); ++l)
    t << "| level " << l << ": unknowns (stored blocks) | " << level_dofs(mg, l) << " ("
      << level_blocks(mg, l) << ") |\n";
  const double prepare = costs.front().prepare_per_step;
  t << "| median PCG iterations per step (warm start) | " << median(stats.iterations) << " |\n"
    << "| median solve / step, ms (wall) | " << std::setprecision(2) << median(stats.solve_ms)
    << " / " << median(stats.step_ms) << " |\n"
    << "| `prepare` per step, in SpMV-equivalents (1 thread) | " << std::setprecision(1)
    << prepare / spmv << " |\n"
    << "| one V-cycle, in SpMV-equivalents (1 thread) | " << costs.front().v_cycle / spmv << " |\n"
    << "| last system from zero: V-cycle PCG, iterations (ms) | " << z.v_cycle.iterations << " ("
    << std::setprecision(2) << z.v_cycle_ms << ") |\n"
    << "| last system from zero: block-Jacobi PCG of the chapter before, iterations (ms) | "
    << z.jacobi.iterations << " (" << z.jacobi_ms << ") |\n"
    << "| last system from zero: Eigen IncompleteCholesky CG, iterations (ms, compute + solve) | "
    << z.ic_iterations << " (" << z.ic_ms << ") |\n\n";
  return t.str();
}

std::string multigrid_table(const LessonRun& run) {
  const ArgParser& args = run.args;
  const Scene& scene = run.scene;
  const SolverSettings solver = solver_from_args(args);
  const MultigridStepperSettings settings = multigrid_from_args(args);
  const std::vector<int> counts = thread_counts_from_args(args, "cost-threads");
  std::cerr << "fem_lessons multigrid: scene " << scene.name << ", mesh " << scene.mesh.file << " ("
            << scene.mesh.num_nodes() << " nodes), " << run.steps << " steps, tol "
            << solver.tolerance << ", smoother " << args.get("smoother") << ", " << max_threads()
            << " thread(s)\n";
  const auto setup_start = Clock::now();
  MultigridStepper stepper(scene, solver, multigrid_params<MultigridRecipe>(settings));
  const double setup_ms = 1e3 * std::chrono::duration<double>(Clock::now() - setup_start).count();
  const RunStats stats = run_chapter(stepper, scene, run.steps);
  Multigrid& mg = stepper.preconditioner().multigrid();
  print_hierarchy(mg, setup_ms);
  std::cerr << "measuring the last system: costs per level, PCG with three preconditioners\n"
            << std::flush;
  const ch07::BlockSparseMatrix& A = stepper.system_matrix();
  const Eigen::VectorXd& b = stepper.system_rhs();
  Eigen::VectorXd x = Eigen::VectorXd::Ones(b.size()), y(b.size());
  const double spmv = time_ms(200, [&] { A.multiply(x, y); });
  std::vector<Costs> costs;
  for (const int threads : counts)
    costs.push_back(measure_costs(mg, b, threads, stats.refreshes, run.steps));
  const FromZero z = from_zero(stepper, scene, solver);
  const std::string per_level = cost_table(mg, costs, spmv, stats, run.steps);
  std::ostringstream t;
  t << main_table(run, mg, stats, z, costs, spmv) << per_level << "\nTolerance "
    << std::defaultfloat << solver.tolerance
    << "; SpMV is one block product with the finest matrix on 1 thread, times are wall-clock "
       "ms (median of repeats). Generated by `fem_lessons multigrid";
  for (const char* option : {"mesh", "steps", "threads", "cost-threads"})
    if (!args.get(option).empty()) t << " --" << option << " " << args.get(option);
  t << " --readme`.\n";
  if (const std::string dir = args.get("export"); !dir.empty()) export_system(run, stepper, z, dir);
  if (!z.v_cycle.converged)
    throw std::runtime_error("the V-cycle PCG did not converge on the last system");
  return t.str();
}

}  // namespace

std::vector<Lesson> lessons() {
  Lesson multigrid{
      "multigrid",
      "the hierarchy, iterations, prepare and V-cycle cost; PCG against block Jacobi and IC",
      "meshes/plate_poster.msh",
      add_multigrid_options,
      [](const LessonRun& run) { return multigrid_table(run); },
      true};
  multigrid.record_args = {"--steps", "100", "--threads", "1", "--cost-threads", "1,2"};
  return {multigrid};
}

}  // namespace fem::ch10
