// Chapter 10's lesson table: `fem_lessons multigrid`, the measurements behind the lesson on
// one scene.
//  - runs chapter 10 for some steps with the multigrid settings given (modes, smoother,
//    sweeps, prolongator) and reports median PCG iterations and solve time per step;
//  - on the last step's filtered system: the hierarchy (levels, unknowns, blocks), the cost
//    of prepare() and of one V-cycle in SpMV-equivalents, and PCG from a zero guess with the
//    V-cycle, with chapter 09's block Jacobi and with Eigen's IncompleteCholesky CG;
//  - with --export DIR: that system as Matrix Market (A.mtx, b.mtx, the filtered rigid-body
//    modes B.mtx) and summary.json, for scripts/pyamg_reference.py.
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
#include "chapters/10_multigrid/report.hpp"
#include "chapters/10_multigrid/stepper.hpp"
#include "common/threads.hpp"

namespace fem::ch10 {

namespace {

using Clock = std::chrono::steady_clock;

Smoother smoother_from(const std::string& name) {
  if (name == "gs") return Smoother::GaussSeidel;
  if (name == "chebyshev") return Smoother::Chebyshev;
  if (name == "jacobi") return Smoother::Jacobi;
  throw UsageError("--smoother must be gs, chebyshev or jacobi");
}

MultigridStepperSettings multigrid_from_args(const ArgParser& args) {
  MultigridStepperSettings settings;
  MultigridSettings& s = settings.multigrid;
  CoarseningSettings& c = s.coarsening;
  SmootherSettings& r = s.relax;
  c.modes = args.get_int("modes");
  r.smoother = smoother_from(args.get("smoother"));
  r.sweeps = args.get_int("sweeps");
  r.l1 = args.get("l1") != "off";
  settings.extrapolation = args.get_int("extrapolate");
  if (settings.extrapolation < 0 || settings.extrapolation > 2)
    throw UsageError("--extrapolate must be 0, 1 or 2");
  s.rows.max_blocks = args.get_int("blocks");
  s.rows.serial_rows = args.get_int("serial-rows");
  r.chebyshev_degree = args.get_int("degree");
  c.improve_candidates = args.get_int("improve");
  c.power_iterations = args.get_int("power");
  if (c.power_iterations < 1) throw UsageError("--power must be at least 1");
  const std::string prolongator = args.get("prolongator");
  if (prolongator != "every-step" && prolongator != "frozen" && prolongator != "tentative")
    throw UsageError("--prolongator must be frozen, every-step or tentative");
  c.smooth_prolongator = prolongator != "tentative";
  c.update_prolongator = prolongator == "every-step";
  s.max_coarse_dofs = args.get_int("max-coarse");
  s.refresh.every = args.get_int("coarse-every");
  s.refresh.growth = args.get_double("growth");
  if (s.refresh.every < 1) throw UsageError("--coarse-every must be at least 1");
  if (c.modes != 3 && c.modes != 6) throw UsageError("--modes must be 3 or 6");
  if (r.sweeps < 1) throw UsageError("--sweeps must be at least 1");
  if (s.max_coarse_dofs < 6) throw UsageError("--max-coarse must be at least 6");
  if (s.rows.max_blocks < 1 || r.chebyshev_degree < 1 || c.improve_candidates < 0 ||
      s.rows.serial_rows < 0)
    throw UsageError(
        "--blocks and --degree must be at least 1, --improve and --serial-rows 0 or more");
  if (!(s.refresh.growth >= 0.0)) throw UsageError("--growth must be 0 (off) or more");
  if (args.get("l1") != "on" && args.get("l1") != "off") throw UsageError("--l1 must be on or off");
  return settings;
}

// The filtered rigid-body modes at the rest positions, 3N x 6: PyAMG's B.
Eigen::MatrixXd rigid_body_modes(const Scene& scene) {
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
  out.refreshes = stepper.multigrid().refresh_rule().refreshes();
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

std::vector<int> cost_thread_counts(const ArgParser& args) {
  std::vector<int> out;
  std::stringstream list(args.get("cost-threads"));
  for (std::string item; std::getline(list, item, ',');) {
    const int n = std::atoi(item.c_str());
    if (n < 1 || std::to_string(n) != item)
      throw UsageError("--cost-threads expects thread counts >= 1 separated by commas");
    if (n > 1 && !openmp_enabled()) throw UsageError("--cost-threads: this build has no OpenMP");
    out.push_back(n);
  }
  if (out.empty()) out = {1, max_threads()};
  if (out.size() == 2 && out[0] == out[1]) out.pop_back();
  return out;
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
  const auto solve = [&](ch09::Preconditioner& M, SolveStats& stats, double& ms) {
    Eigen::VectorXd y = Eigen::VectorXd::Zero(b.size());
    stats = pcg.solve(A, M, b, solver, y);
    ms = time_ms(5, [&] {
      y.setZero();
      pcg.solve(A, M, b, solver, y);
    });
  };
  VCyclePreconditioner v_cycle(stepper.multigrid());
  solve(v_cycle, out.v_cycle, out.v_cycle_ms);
  ch09::BlockJacobi block_jacobi(stepper.diagonal_blocks());
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

// The last system as Matrix Market for scripts/pyamg_reference.py, and a summary.
void export_system(const LessonRun& run, const MultigridStepper& stepper, const FromZero& z,
                   const std::string& dir) {
  const Scene& scene = run.scene;
  const Eigen::SparseMatrix<double> csc = stepper.system_matrix().to_sparse();
  const Eigen::VectorXd& b = stepper.system_rhs();
  std::filesystem::create_directories(dir);
  if (!Eigen::saveMarket(csc, dir + "/A.mtx") || !Eigen::saveMarketVector(b, dir + "/b.mtx") ||
      !Eigen::saveMarket(Eigen::SparseMatrix<double>(rigid_body_modes(scene).sparseView()),
                         dir + "/B.mtx"))
    throw std::runtime_error("cannot write Matrix Market files into '" + dir + "'");
  std::ofstream(dir + "/summary.json")
      << "{\"mesh\": \"" << mesh_name(scene) << "\", \"scene\": \"" << scene.name
      << "\", \"nodes\": " << scene.mesh.num_nodes() << ", \"tolerance\": " << std::defaultfloat
      << solver_from_args(run.args).tolerance << ", \"ours_iterations\": " << z.v_cycle.iterations
      << ", \"block_jacobi_iterations\": " << z.jacobi.iterations
      << ", \"ours_levels\": " << stepper.multigrid().levels() << "}\n";
  std::cerr << "wrote " << dir << "/{A,b,B}.mtx and summary.json\n";
}

void print_hierarchy(const Multigrid& mg, double setup_ms) {
  std::cerr << "\nhierarchy (set-up " << std::fixed << std::setprecision(1) << setup_ms
            << " ms for the whole stepper)\n";
  long long blocks = 0, fine_blocks = 0;
  for (int l = 0; l < mg.levels(); ++l) {
    const int block = l == 0 ? 3 : 6;
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
  const std::vector<int> counts = cost_thread_counts(args);
  std::cerr << "fem_lessons multigrid: scene " << scene.name << ", mesh " << scene.mesh.file << " ("
            << scene.mesh.num_nodes() << " nodes), " << run.steps << " steps, tol "
            << solver.tolerance << ", smoother " << args.get("smoother") << ", " << max_threads()
            << " thread(s)\n";
  const auto setup_start = Clock::now();
  MultigridStepper stepper(scene, solver, settings);
  const double setup_ms = 1e3 * std::chrono::duration<double>(Clock::now() - setup_start).count();
  const RunStats stats = run_chapter(stepper, scene, run.steps);
  Multigrid& mg = stepper.multigrid();
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
  std::cerr << "\n" << per_level;
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

const char* smoother_name(Smoother smoother) {
  switch (smoother) {
    case Smoother::GaussSeidel:
      return "gs";
    case Smoother::Chebyshev:
      return "chebyshev";
    default:
      return "jacobi";
  }
}

// The options' defaults are the chapter's (MultigridStepperSettings{}).
void add_multigrid_options(ArgParser& args) {
  const MultigridStepperSettings defaults;
  const MultigridSettings& d = defaults.multigrid;
  const auto text = [](auto value) {
    std::ostringstream s;
    s << value;
    return s.str();
  };
  add_solver_options(args);
  args.option("modes", "N", "near-null-space modes per aggregate: 6 or 3 (translations)",
              text(d.coarsening.modes));
  args.option("smoother", "NAME",
              "gs (l1-hybrid block Gauss-Seidel), chebyshev (on block Jacobi) or jacobi",
              smoother_name(d.relax.smoother));
  args.option("sweeps", "N", "pre- and post-smoothing sweeps", text(d.relax.sweeps));
  args.option("l1", "on|off", "Gauss-Seidel: the l1 term on the couplings between row blocks",
              d.relax.l1 ? "on" : "off");
  args.option("blocks", "N", "at most N fixed row blocks per level (1: sequential Gauss-Seidel)",
              text(d.rows.max_blocks));
  args.option("serial-rows", "N", "levels of fewer rows run on one thread",
              text(d.rows.serial_rows));
  args.option("degree", "N", "Chebyshev: the polynomial's degree", text(d.relax.chebyshev_degree));
  args.option("power", "N", "power iterations of the first estimate of rho(D^-1 A) on each level",
              text(d.coarsening.power_iterations));
  args.option("improve", "N", "symmetric Gauss-Seidel sweeps on the rigid-body modes at set-up",
              text(d.coarsening.improve_candidates));
  args.option("extrapolate", "ORDER",
              "the guess: 0 the last solution, 1 the line through the last two, 2 the parabola "
              "through the last three",
              text(defaults.extrapolation));
  args.option("prolongator", "KIND",
              "frozen (smoothed on the first step), every-step (smoothed at every refresh) or "
              "tentative (unsmoothed)",
              d.coarsening.update_prolongator   ? "every-step"
              : d.coarsening.smooth_prolongator ? "frozen"
                                                : "tentative");
  args.option("max-coarse", "N", "largest level solved by dense Cholesky, in unknowns",
              text(d.max_coarse_dofs));
  args.option("coarse-every", "K", "recompute the coarse matrices every K-th step",
              text(d.refresh.every));
  args.option("growth", "G",
              "and earlier when a solve takes more than G times the V-cycles after the last "
              "refresh (0: never)",
              text(d.refresh.growth));
  args.option("export", "DIR", "write the last filtered system as Matrix Market into DIR", "");
  args.option("cost-threads", "LIST",
              "thread counts of the cost table, comma-separated (default: 1 and --threads)", "");
}

}  // namespace

std::vector<Lesson> lessons() {
  return {{"multigrid",
           "the hierarchy, iterations, prepare and V-cycle cost; PCG against block Jacobi and IC",
           "meshes/plate_poster.msh", add_multigrid_options,
           [](const LessonRun& run) { return multigrid_table(run); }, true}};
}

}  // namespace fem::ch10
