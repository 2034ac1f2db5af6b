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

#include "chapters/09_threads/parallel_pcg.hpp"
#include "chapters/10_multigrid/stepper.hpp"
#include "common/threads.hpp"

namespace fem::ch10 {

namespace {

using Clock = std::chrono::steady_clock;

MultigridSettings::Smoother smoother_from(const std::string& name) {
  if (name == "gs") return MultigridSettings::Smoother::GaussSeidel;
  if (name == "chebyshev") return MultigridSettings::Smoother::Chebyshev;
  if (name == "jacobi") return MultigridSettings::Smoother::Jacobi;
  throw UsageError("--smoother must be gs, chebyshev or jacobi");
}

MultigridSettings multigrid_from_args(const ArgParser& args) {
  MultigridSettings s;
  s.modes = args.get_int("modes");
  s.smoother = smoother_from(args.get("smoother"));
  s.sweeps = args.get_int("sweeps");
  s.l1 = args.get("l1") != "off";
  s.max_blocks = args.get_int("blocks");
  s.serial_rows = args.get_int("serial-rows");
  s.chebyshev_degree = args.get_int("degree");
  s.improve_candidates = args.get_int("improve");
  const std::string prolongator = args.get("prolongator");
  if (prolongator != "every-step" && prolongator != "frozen" && prolongator != "tentative")
    throw UsageError("--prolongator must be frozen, every-step or tentative");
  s.smooth_prolongator = prolongator != "tentative";
  s.update_prolongator = prolongator == "every-step";
  s.max_coarse_dofs = args.get_int("max-coarse");
  s.coarse_refresh = args.get_int("coarse-every");
  s.refresh_growth = args.get_double("growth");
  if (s.coarse_refresh < 1) throw UsageError("--coarse-every must be at least 1");
  if (s.modes != 3 && s.modes != 6) throw UsageError("--modes must be 3 or 6");
  if (s.sweeps < 1) throw UsageError("--sweeps must be at least 1");
  if (s.max_coarse_dofs < 6) throw UsageError("--max-coarse must be at least 6");
  if (s.max_blocks < 1 || s.chebyshev_degree < 1 || s.improve_candidates < 0 || s.serial_rows < 0)
    throw UsageError("--blocks and --degree must be at least 1, --improve and --serial-rows 0 or more");
  if (!(s.refresh_growth >= 0.0)) throw UsageError("--growth must be 0 (off) or more");
  if (args.get("l1") != "on" && args.get("l1") != "off") throw UsageError("--l1 must be on or off");
  return s;
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

std::string multigrid_table(const LessonRun& run) {
  const ArgParser& args = run.args;
  const int threads = max_threads();
  const Scene& scene = run.scene;
  const SolverSettings solver = solver_from_args(args);
  const MultigridSettings settings = multigrid_from_args(args);
  const int steps = run.steps;

  std::cerr << "fem_lessons multigrid: scene " << scene.name << ", mesh " << scene.mesh.file << " ("
            << scene.mesh.num_nodes() << " nodes), " << steps << " steps, tol "
            << solver.tolerance << ", modes " << settings.modes << ", smoother "
            << args.get("smoother") << " x" << settings.sweeps << ", prolongator "
            << args.get("prolongator") << ", " << threads << " thread(s)\n";
  const auto setup_start = Clock::now();
  MultigridStepper stepper(scene, solver, settings);
  const double setup_ms = 1e3 * std::chrono::duration<double>(Clock::now() - setup_start).count();
  State state = rest_state(scene);
  std::vector<double> iterations, solve_ms, step_ms;
  for (int k = 0; k < steps; ++k) {
    stepper.step(state);
    const StepProfile& p = stepper.profile();
    if (const char* why = divergence(state, p)) {
      throw std::runtime_error("diverged at step " + std::to_string(k + 1) + ": " + why);
    }
    iterations.push_back(p.cg_iterations);
    solve_ms.push_back(1e3 * p.solve.seconds);
    step_ms.push_back(1e3 * p.step.seconds);
    if ((k + 1) % std::max(1, steps / 4) == 0)
      std::cerr << "  step " << k + 1 << "/" << steps << "\n" << std::flush;
  }

  Multigrid& mg = stepper.multigrid();
  const ch07::BlockSparseMatrix& A = stepper.system_matrix();
  const Eigen::VectorXd& b = stepper.system_rhs();
  std::cerr << "\nhierarchy (set-up " << std::fixed << std::setprecision(1) << setup_ms
            << " ms for the whole stepper)\n";
  long long blocks = 0, fine_blocks = 0;
  for (int l = 0; l < mg.levels(); ++l) {
    const int block = l == 0 ? 3 : 6;
    std::cerr << "  level " << l << ": " << std::setw(7) << mg.level_dofs(l) << " unknowns, "
              << std::setw(8) << mg.level_blocks(l) << " blocks of " << block << "x" << block;
    if (l + 1 < mg.levels())
      std::cerr << ", P " << std::setw(7) << mg.prolongator_blocks(l) << " blocks of " << block
                << "x6";
    std::cerr << "\n";
    blocks += mg.level_blocks(l) * block * block;
    if (l == 0) fine_blocks = blocks;
  }
  std::cerr << "  operator complexity (stored entries, all levels / finest): " << std::setprecision(2)
            << static_cast<double>(blocks) / fine_blocks << "\n";

  std::cerr << "measuring the last system: V-cycle, PCG with three preconditioners\n"
            << std::flush;
  const int repeat = 20;
  Eigen::VectorXd x = Eigen::VectorXd::Ones(b.size()), y(b.size());
  const double spmv = time_ms(10 * repeat, [&] { A.multiply(x, y); });
  const double prepare = time_ms(repeat, [&] { mg.prepare(A.blocks); });
  const double vcycle = time_ms(10 * repeat, [&] { mg.apply(b, y); });

  // PCG from zero on the same system: the V-cycle, block Jacobi, Eigen's IC.
  ch09::ParallelPcg pcg(A, scene.constraints);
  VCyclePreconditioner v_cycle(mg);
  Eigen::VectorXd y10 = Eigen::VectorXd::Zero(b.size());
  const SolveStats r10 = pcg.solve(A, v_cycle, b, solver, y10);
  const double pcg10 = time_ms(5, [&] {
    y10.setZero();
    pcg.solve(A, v_cycle, b, solver, y10);
  });
  ch09::BlockJacobi block_jacobi(stepper.diagonal_blocks());
  Eigen::VectorXd y9 = Eigen::VectorXd::Zero(b.size());
  const SolveStats r9 = pcg.solve(A, block_jacobi, b, solver, y9);
  const double pcg9_ms = time_ms(5, [&] {
    y9.setZero();
    pcg.solve(A, block_jacobi, b, solver, y9);
  });
  const Eigen::SparseMatrix<double> csc = A.to_sparse();
  Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper,
                           Eigen::IncompleteCholesky<double>>
      ic;
  ic.setTolerance(solver.tolerance);
  ic.setMaxIterations(solver.max_iterations);
  Eigen::VectorXd yic;
  const double ic_ms = time_ms(3, [&] {
    ic.compute(csc);
    yic = ic.solve(b);
  });

  std::cerr << std::setprecision(3) << "\nchapter 10 over " << steps
            << " steps (warm start): median iterations " << median(iterations)
            << ", median solve " << median(solve_ms) << " ms, median step " << median(step_ms)
            << " ms\n"
            << "on the last system: SpMV " << spmv << " ms, prepare " << prepare << " ms ("
            << std::setprecision(1) << prepare / spmv << " SpMV), one V-cycle "
            << std::setprecision(3) << vcycle << " ms (" << std::setprecision(1) << vcycle / spmv
            << " SpMV)\n"
            << std::setprecision(3) << "PCG from zero, tol " << std::defaultfloat << solver.tolerance << std::fixed
            << " (ms):\n"
            << "  V-cycle (chapter 10)          " << std::setw(5) << r10.iterations
            << " iterations, " << pcg10 << " ms (plus prepare)\n"
            << "  block Jacobi (chapter 09)     " << std::setw(5) << r9.iterations
            << " iterations, " << pcg9_ms << " ms\n"
            << "  Eigen IncompleteCholesky CG   " << std::setw(5) << ic.iterations()
            << " iterations, " << ic_ms << " ms (compute + solve)\n";

  std::string table;
  {
    std::ostringstream t;
    t << std::fixed << std::setprecision(1);
    t << "| `" << mesh_name(scene) << "`, "
      << scene.name << ", " << steps << " steps, " << threads << " thread(s) | value |\n"
      << "| --- | ---: |\n";
    for (int l = 0; l < mg.levels(); ++l)
      t << "| level " << l << ": unknowns (stored blocks) | " << mg.level_dofs(l) << " ("
        << mg.level_blocks(l) << ") |\n";
    t << "| median PCG iterations per step (warm start) | " << median(iterations) << " |\n"
      << "| median solve / step, ms (wall) | " << std::setprecision(2) << median(solve_ms)
      << " / " << median(step_ms) << " |\n"
      << "| `prepare`, in SpMV-equivalents | " << std::setprecision(1) << prepare / spmv << " |\n"
      << "| one V-cycle, in SpMV-equivalents | " << vcycle / spmv << " |\n"
      << "| last system from zero: V-cycle PCG, iterations (ms, plus `prepare`) | "
      << r10.iterations << " (" << std::setprecision(2) << pcg10 << " + " << prepare << ") |\n"
      << "| last system from zero: block-Jacobi PCG of the chapter before, iterations (ms) | "
      << r9.iterations << " (" << pcg9_ms << ") |\n"
      << "| last system from zero: Eigen IncompleteCholesky CG, iterations (ms, compute + solve) | "
      << ic.iterations() << " (" << ic_ms << ") |\n\n"
      << "Tolerance " << std::defaultfloat << solver.tolerance
      << "; SpMV is one block product with the finest matrix, times are wall-clock ms "
         "(median of repeats). Generated by `fem_lessons multigrid";
    for (const char* option : {"mesh", "steps", "threads"})
      if (!args.get(option).empty()) t << " --" << option << " " << args.get(option);
    t << " --readme`.\n";
    table = t.str();
  }
  if (const std::string dir = args.get("export"); !dir.empty()) {
    std::filesystem::create_directories(dir);
    if (!Eigen::saveMarket(csc, dir + "/A.mtx") || !Eigen::saveMarketVector(b, dir + "/b.mtx") ||
        !Eigen::saveMarket(Eigen::SparseMatrix<double>(rigid_body_modes(scene).sparseView()),
                           dir + "/B.mtx"))
      throw std::runtime_error("cannot write Matrix Market files into '" + dir + "'");
    std::ofstream(dir + "/summary.json")
        << "{\"mesh\": \"" << mesh_name(scene)
        << "\", \"scene\": \"" << scene.name << "\", \"nodes\": " << scene.mesh.num_nodes()
        << ", \"tolerance\": " << std::defaultfloat << solver.tolerance << ", \"ours_iterations\": " << r10.iterations
        << ", \"block_jacobi_iterations\": " << r9.iterations
        << ", \"ours_levels\": " << mg.levels() << "}\n";
    std::cerr << "wrote " << dir << "/{A,b,B}.mtx and summary.json\n";
  }
  if (!r10.converged) throw std::runtime_error("the V-cycle PCG did not converge on the last system");
  return table;
}


void add_multigrid_options(ArgParser& args) {
  add_solver_options(args);
  args.option("modes", "N", "near-null-space modes per aggregate: 6 or 3 (translations)", "6");
  args.option("smoother", "NAME",
              "gs (l1-hybrid block Gauss-Seidel), chebyshev (on block Jacobi) or jacobi", "gs");
  args.option("sweeps", "N", "pre- and post-smoothing sweeps", "1");
  args.option("l1", "on|off", "Gauss-Seidel: the l1 term on the couplings between row blocks", "on");
  args.option("blocks", "N", "at most N fixed row blocks per level (1: sequential Gauss-Seidel)", "64");
  args.option("serial-rows", "N", "levels of fewer rows run on one thread", "0");
  args.option("degree", "N", "Chebyshev: the polynomial's degree", "2");
  args.option("improve", "N", "symmetric Gauss-Seidel sweeps on the rigid-body modes at set-up", "0");
  args.option("prolongator", "KIND",
              "frozen (smoothed on the first step), every-step (smoothed every step) or "
              "tentative (unsmoothed)",
              "frozen");
  args.option("max-coarse", "N", "largest level solved by dense Cholesky, in unknowns", "200");
  args.option("coarse-every", "K", "recompute the coarse matrices every K-th step", "1");
  args.option("growth", "G",
              "and earlier when a solve takes more than G times the V-cycles after the last "
              "refresh (0: never)",
              "1.25");
  args.option("export", "DIR", "write the last filtered system as Matrix Market into DIR", "");
}

}  // namespace

std::vector<Lesson> lessons() {
  return {{"multigrid",
           "the hierarchy, iterations, prepare and V-cycle cost; PCG against block Jacobi and IC",
           "meshes/plate_poster.msh", add_multigrid_options,
           [](const LessonRun& run) { return multigrid_table(run); }}};
}

}  // namespace fem::ch10
