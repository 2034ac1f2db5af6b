// fem_multigrid: the measurements behind chapter 10's lesson, on one scene.
//  - runs chapter 10 for some steps with the multigrid settings given (modes, smoother,
//    sweeps, prolongator) and reports median PCG iterations and solve time per step;
//  - on the last step's filtered system: the hierarchy (levels, unknowns, blocks), the cost
//    of prepare() and of one V-cycle in SpMV-equivalents, and PCG from a zero guess with the
//    V-cycle, with chapter 09's block Jacobi and with Eigen's IncompleteCholesky CG;
//  - with --readme FILE: those numbers as a table between the markers
//    <!-- multigrid-table:begin/end --> of FILE (the chapter's README);
//  - with --export DIR: that system as Matrix Market (A.mtx, b.mtx, the filtered rigid-body
//    modes B.mtx) and summary.json, for scripts/pyamg_reference.py.
#include <Eigen/IterativeLinearSolvers>
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <string>
#include <ctime>
#include <unsupported/Eigen/SparseExtra>
#include <vector>

#include "chapters/09_threads/stepper.hpp"
#include "chapters/10_multigrid/stepper.hpp"
#include "common/cli.hpp"
#include "common/model.hpp"

namespace {

using namespace fem;
using Clock = std::chrono::steady_clock;

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

double thread_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// Median CPU milliseconds of this thread over `repeat` runs of f: on a shared machine the
// wall clock of a long run also counts the other processes' time slices, the CPU time does
// not, so the ratios between short and long operations stay meaningful.
template <class F>
double time_ms(int repeat, F&& f) {
  std::vector<double> ms;
  for (int k = 0; k < repeat; ++k) {
    const double start = thread_seconds();
    f();
    ms.push_back(1e3 * (thread_seconds() - start));
  }
  return median(ms);
}

ch10::MultigridSettings multigrid_from_args(const ArgParser& args) {
  ch10::MultigridSettings s;
  s.modes = args.get_int("modes");
  const std::string smoother = args.get("smoother");
  if (smoother == "gs")
    s.smoother = ch10::MultigridSettings::Smoother::GaussSeidel;
  else if (smoother == "jacobi")
    s.smoother = ch10::MultigridSettings::Smoother::Jacobi;
  else
    throw UsageError("--smoother must be gs or jacobi");
  s.sweeps = args.get_int("sweeps");
  const std::string prolongator = args.get("prolongator");
  if (prolongator != "every-step" && prolongator != "frozen" && prolongator != "tentative")
    throw UsageError("--prolongator must be frozen, every-step or tentative");
  s.smooth_prolongator = prolongator != "tentative";
  s.update_prolongator = prolongator == "every-step";
  s.max_coarse_dofs = args.get_int("max-coarse");
  s.coarse_refresh = args.get_int("coarse-every");
  if (s.coarse_refresh < 1) throw UsageError("--coarse-every must be at least 1");
  if (s.modes != 3 && s.modes != 6) throw UsageError("--modes must be 3 or 6");
  if (s.sweeps < 1) throw UsageError("--sweeps must be at least 1");
  if (s.max_coarse_dofs < 6) throw UsageError("--max-coarse must be at least 6");
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

int run(const ArgParser& args) {
  const int threads = threads_from_args(args);
  const Scene scene = scene_from_args(args);
  const SolverSettings solver = solver_from_args(args);
  const ch10::MultigridSettings settings = multigrid_from_args(args);
  const int steps = args.get_int("steps");
  if (steps <= 0) throw UsageError("--steps must be positive");

  std::cout << "fem_multigrid: scene " << scene.name << ", mesh " << scene.mesh.file << " ("
            << scene.mesh.num_nodes() << " nodes), " << steps << " steps, tol "
            << solver.tolerance << ", modes " << settings.modes << ", smoother "
            << args.get("smoother") << " x" << settings.sweeps << ", prolongator "
            << args.get("prolongator") << ", " << threads << " thread(s)\n";
  const auto setup_start = Clock::now();
  ch10::MultigridStepper stepper(scene, solver, settings);
  const double setup_ms = 1e3 * std::chrono::duration<double>(Clock::now() - setup_start).count();
  State state = rest_state(scene);
  std::vector<double> iterations, solve_ms, step_ms;
  for (int k = 0; k < steps; ++k) {
    stepper.step(state);
    const StepProfile& p = stepper.profile();
    if (const char* why = divergence(state, p)) {
      std::cerr << "fem_multigrid: diverged at step " << k + 1 << ": " << why << "\n";
      return 1;
    }
    iterations.push_back(p.cg_iterations);
    solve_ms.push_back(1e3 * p.solve.seconds);
    step_ms.push_back(1e3 * p.step.seconds);
    if ((k + 1) % std::max(1, steps / 4) == 0)
      std::cout << "  step " << k + 1 << "/" << steps << "\n" << std::flush;
  }

  ch10::Multigrid& mg = stepper.multigrid();
  const ch10::BlockSparseMatrix& A = stepper.system_matrix();
  const Eigen::VectorXd& b = stepper.system_rhs();
  std::cout << "\nhierarchy (set-up " << std::fixed << std::setprecision(1) << setup_ms
            << " ms for the whole stepper)\n";
  long long blocks = 0, fine_blocks = 0;
  for (int l = 0; l < mg.levels(); ++l) {
    const int block = l == 0 ? 3 : 6;
    std::cout << "  level " << l << ": " << std::setw(7) << mg.level_dofs(l) << " unknowns, "
              << std::setw(8) << mg.level_blocks(l) << " blocks of " << block << "x" << block;
    if (l + 1 < mg.levels())
      std::cout << ", P " << std::setw(7) << mg.prolongator_blocks(l) << " blocks of " << block
                << "x6";
    std::cout << "\n";
    blocks += mg.level_blocks(l) * block * block;
    if (l == 0) fine_blocks = blocks;
  }
  std::cout << "  operator complexity (stored entries, all levels / finest): " << std::setprecision(2)
            << static_cast<double>(blocks) / fine_blocks << "\n";

  std::cout << "measuring the last system: V-cycle, PCG with three preconditioners\n"
            << std::flush;
  const int repeat = 20;
  Eigen::VectorXd x = Eigen::VectorXd::Ones(b.size()), y(b.size());
  const double spmv = time_ms(10 * repeat, [&] { A.multiply(x, y); });
  const double prepare = time_ms(repeat, [&] { mg.prepare(A.blocks); });
  const double vcycle = time_ms(10 * repeat, [&] { mg.apply(b, y); });

  // PCG from zero on the same system: the V-cycle, block Jacobi, Eigen's IC.
  ch10::ParallelPcg pcg(A, scene.constraints);
  Eigen::VectorXd y10 = Eigen::VectorXd::Zero(b.size());
  const ch10::PcgResult r10 = pcg.solve(A, mg, b, solver, y10);
  const double pcg10 = time_ms(5, [&] {
    y10.setZero();
    pcg.solve(A, mg, b, solver, y10);
  });
  ch09::BlockSparseMatrix A9;
  A9.row_start = A.row_start;
  A9.column = A.column;
  A9.blocks = A.blocks;
  ch09::ParallelPcg pcg9(A9, stepper.diagonal_blocks(), scene.constraints);
  Eigen::VectorXd y9 = Eigen::VectorXd::Zero(b.size());
  const ch09::PcgResult r9 = pcg9.solve(A9, b, solver, y9);
  const double pcg9_ms = time_ms(5, [&] {
    y9.setZero();
    pcg9.solve(A9, b, solver, y9);
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

  std::cout << std::setprecision(3) << "\nchapter 10 over " << steps
            << " steps (warm start): median iterations " << median(iterations)
            << ", median solve " << median(solve_ms) << " ms, median step " << median(step_ms)
            << " ms\n"
            << "on the last system: SpMV " << spmv << " ms, prepare " << prepare << " ms ("
            << std::setprecision(1) << prepare / spmv << " SpMV), one V-cycle "
            << std::setprecision(3) << vcycle << " ms (" << std::setprecision(1) << vcycle / spmv
            << " SpMV)\n"
            << std::setprecision(3) << "PCG from zero, tol " << std::defaultfloat << solver.tolerance << std::fixed
            << " (CPU ms of this thread):\n"
            << "  V-cycle (chapter 10)          " << std::setw(5) << r10.iterations
            << " iterations, " << pcg10 << " ms (plus prepare)\n"
            << "  block Jacobi (chapter 09)     " << std::setw(5) << r9.iterations
            << " iterations, " << pcg9_ms << " ms\n"
            << "  Eigen IncompleteCholesky CG   " << std::setw(5) << ic.iterations()
            << " iterations, " << ic_ms << " ms (compute + solve)\n";

  if (const std::string readme = args.get("readme"); !readme.empty()) {
    std::ostringstream t;
    t << std::fixed << std::setprecision(1);
    t << "| `" << std::filesystem::path(scene.mesh.file).filename().string() << "`, "
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
      << "| last system from zero: V-cycle PCG, iterations (CPU ms, plus `prepare`) | "
      << r10.iterations << " (" << std::setprecision(2) << pcg10 << " + " << prepare << ") |\n"
      << "| last system from zero: block-Jacobi PCG of the chapter before, iterations (CPU ms) | "
      << r9.iterations << " (" << pcg9_ms << ") |\n"
      << "| last system from zero: Eigen IncompleteCholesky CG, iterations (CPU ms, compute + solve) | "
      << ic.iterations() << " (" << ic_ms << ") |\n\n"
      << "Tolerance " << std::defaultfloat << solver.tolerance
      << "; SpMV is one block product with the finest matrix, times are CPU ms of the thread "
         "(median of repeats). Generated by `fem_multigrid";
    for (const char* option : {"mesh", "steps", "threads"})
      if (!args.get(option).empty()) t << " --" << option << " " << args.get(option);
    t << " --readme`.\n";
    write_between_markers(readme, "multigrid-table", t.str());
    std::cout << "wrote " << readme << "\n";
  }
  if (const std::string dir = args.get("export"); !dir.empty()) {
    std::filesystem::create_directories(dir);
    if (!Eigen::saveMarket(csc, dir + "/A.mtx") || !Eigen::saveMarketVector(b, dir + "/b.mtx") ||
        !Eigen::saveMarket(Eigen::SparseMatrix<double>(rigid_body_modes(scene).sparseView()),
                           dir + "/B.mtx"))
      throw std::runtime_error("cannot write Matrix Market files into '" + dir + "'");
    std::ofstream(dir + "/summary.json")
        << "{\"mesh\": \"" << std::filesystem::path(scene.mesh.file).filename().string()
        << "\", \"scene\": \"" << scene.name << "\", \"nodes\": " << scene.mesh.num_nodes()
        << ", \"tolerance\": " << std::defaultfloat << solver.tolerance << ", \"ours_iterations\": " << r10.iterations
        << ", \"block_jacobi_iterations\": " << r9.iterations
        << ", \"ours_levels\": " << mg.levels() << "}\n";
    std::cout << "wrote " << dir << "/{A,b,B}.mtx and summary.json\n";
  }
  return r10.converged ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  ArgParser args("fem_multigrid",
                 "Chapter 10's multigrid on one scene: iterations, hierarchy, V-cycle cost, "
                 "PCG against block Jacobi and Eigen's IncompleteCholesky; exports the system.");
  add_scene_options(args, "meshes/plate_poster.msh");
  add_solver_options(args);
  args.option("steps", "N", "steps to run before measuring the last system", "20");
  args.option("modes", "N", "near-null-space modes per aggregate: 6 or 3 (translations)", "6");
  args.option("smoother", "NAME", "gs (symmetric block Gauss-Seidel) or jacobi", "gs");
  args.option("sweeps", "N", "pre- and post-smoothing sweeps", "1");
  args.option("prolongator", "KIND",
              "frozen (smoothed on the first step), every-step (smoothed every step) or "
              "tentative (unsmoothed)",
              "frozen");
  args.option("max-coarse", "N", "largest level solved by dense Cholesky, in unknowns", "200");
  args.option("coarse-every", "K", "recompute the coarse matrices every K-th step", "1");
  add_thread_option(args);
  args.option("readme", "FILE", "also write the table between the multigrid-table markers of FILE",
              "");
  args.option("export", "DIR", "write the last filtered system as Matrix Market into DIR", "");
  try {
    if (!args.parse(argc, argv)) return 0;
    return run(args);
  } catch (const UsageError& e) {
    std::cerr << "fem_multigrid: " << e.what() << " (see fem_multigrid --help)\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "fem_multigrid: error: " << e.what() << "\n";
    return 1;
  }
}
