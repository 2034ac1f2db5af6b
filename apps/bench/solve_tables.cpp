#include "apps/bench/solve_tables.hpp"

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCholesky>
#ifdef FEM_HAVE_CHOLMOD
#include <Eigen/CholmodSupport>
#endif
#include <chrono>
#include <functional>
#include <iostream>
#include <stdexcept>

#include "chapters/06_custom_pcg/stepper.hpp"
#include "chapters/09_threads/stepper.hpp"
#include "common/alloc_counter.hpp"
#include "common/statistics.hpp"
#include "common/threads.hpp"

namespace fem::bench {

namespace {

using SparseMatrix = Eigen::SparseMatrix<double>;
using RowMajorMatrix = Eigen::SparseMatrix<double, Eigen::RowMajor>;
using Clock = std::chrono::steady_clock;

double ms_between(Clock::time_point a, Clock::time_point b) {
  return 1e3 * std::chrono::duration<double>(b - a).count();
}

// One row's measured solves.
struct Samples {
  std::vector<double> total, setup, solve, iterations, allocations;

  SolverResult result(const std::string& name) const {
    return {name,          median(total),      median(setup),
            median(solve), median(iterations), median(allocations)};
  }
};

// The stock solvers of the single-threaded rows, with the chapters' tolerance and cap.
struct StockSolvers {
  Eigen::ConjugateGradient<SparseMatrix> cg;
  Eigen::ConjugateGradient<SparseMatrix, Eigen::Lower | Eigen::Upper> cg_full;
  Eigen::ConjugateGradient<SparseMatrix, Eigen::Lower | Eigen::Upper,
                           Eigen::IncompleteCholesky<double>>
      cg_ichol;
  Eigen::SimplicialLDLT<SparseMatrix> ldlt;
#ifdef FEM_HAVE_CHOLMOD
  Eigen::CholmodSupernodalLLT<SparseMatrix> cholmod;
#endif

  explicit StockSolvers(const SolverSettings& settings) {
    const auto configure = [&settings](auto& solver) {
      solver.setTolerance(settings.tolerance);  // Eigen's default is machine epsilon
      solver.setMaxIterations(settings.max_iterations);
    };
    configure(cg);
    configure(cg_full);
    configure(cg_ichol);
  }
  // The pattern is the same for every system: analysed once.
  void analyze(const SparseMatrix& A) {
    cg_ichol.analyzePattern(A);
    ldlt.analyzePattern(A);
#ifdef FEM_HAVE_CHOLMOD
    cholmod.analyzePattern(A);
#endif
  }
};

// The single-threaded rows: every solver on one system after the other.
class SolveTable {
 public:
  SolveTable(const Scene& scene, const SolverSettings& settings, Eigen::Index dofs)
      : scene_(scene), settings_(settings), stock_(settings) {
    previous_ = Eigen::VectorXd::Zero(dofs);
#ifdef FEM_HAVE_CHOLMOD
    names_.push_back("cholmod_llt");
#endif
    samples_.resize(names_.size());
  }

  // Every row on A y = b, each from the same inputs; kept when `measured`.
  void solve(const SparseMatrix& A, const Eigen::VectorXd& b, bool measured) {
    b_ = &b;
    measured_ = measured;
    if (offsets_.empty()) {
      offsets_ = ch06::diagonal_offsets(A);
      stock_.analyze(A);
    }
    measure(
        0, [&] { stock_.cg.compute(A); }, iterative(stock_.cg, false));
    measure(
        1, [&] { stock_.cg.compute(A); }, iterative(stock_.cg, true));
    measure(
        2, [] {}, [&] { return ours(A); });
    measure(
        3, [&] { stock_.cg_full.compute(A); }, iterative(stock_.cg_full, false));
    measure(
        4, [&] { stock_.cg_full.compute(A); }, iterative(stock_.cg_full, true));
    measure(
        5, [&] { stock_.cg_ichol.factorize(A); }, iterative(stock_.cg_ichol, true));
    measure(
        6, [&] { stock_.ldlt.factorize(A); }, direct(stock_.ldlt));
#ifdef FEM_HAVE_CHOLMOD
    measure(
        7, [&] { stock_.cholmod.factorize(A); }, direct(stock_.cholmod));
#endif
    previous_ = ours_;  // the next system's guess: this one's solution
  }

  std::vector<SolverResult> results() const {
    std::vector<SolverResult> out;
    for (std::size_t i = 0; i < names_.size(); ++i) out.push_back(samples_[i].result(names_[i]));
    return out;
  }

 private:
  void measure(std::size_t row, const std::function<void()>& setup,
               const std::function<double()>& solve) {
    alloc::Scope scope;
    const auto start = Clock::now();
    setup();
    const auto middle = Clock::now();
    const double iterations = solve();
    const auto end = Clock::now();
    const long long allocations = scope.allocations();
    if (!measured_) return;
    Samples& s = samples_[row];
    s.total.push_back(ms_between(start, end));
    s.setup.push_back(ms_between(start, middle));
    s.solve.push_back(ms_between(middle, end));
    s.iterations.push_back(iterations);
    s.allocations.push_back(static_cast<double>(allocations));
  }

  template <class Solver>
  std::function<double()> iterative(Solver& solver, bool guess) {
    return [this, &solver, guess] {
      if (guess)
        x_ = solver.solveWithGuess(*b_, previous_);
      else
        x_ = solver.solve(*b_);
      if (solver.info() != Eigen::Success && solver.iterations() < solver.maxIterations())
        throw std::runtime_error("the solve table: an Eigen CG failed");
      return static_cast<double>(solver.iterations());
    };
  }

  template <class Solver>
  std::function<double()> direct(Solver& solver) {
    return [this, &solver] {
      x_ = solver.solve(*b_);
      if (solver.info() != Eigen::Success)
        throw std::runtime_error("the solve table: a direct solver failed");
      return 0.0;
    };
  }

  double ours(const SparseMatrix& A) {
    x_ = previous_;
    const double iterations =
        ch06::pcg_solve(A, *b_, scene_.constraints, offsets_, settings_, work_, x_).iterations;
    ours_ = x_;
    return iterations;
  }

  const Scene& scene_;
  const SolverSettings& settings_;
  StockSolvers stock_;
  ch06::PcgWorkspace work_;
  std::vector<int> offsets_;
  const Eigen::VectorXd* b_ = nullptr;
  bool measured_ = false;
  Eigen::VectorXd previous_, x_, ours_;
  std::vector<std::string> names_ = {"eigen_cg",      "eigen_cg_guess",      "pcg_ch06",
                                     "eigen_cg_full", "eigen_cg_full_guess", "eigen_cg_ichol",
                                     "eigen_ldlt"};
  std::vector<Samples> samples_;
};

// A threaded row: Eigen's row-major CG or chapter 09's PCG, on `threads` threads.
struct ThreadedRow {
  std::string name;
  int threads = 1;
  bool eigen = false;
  Samples samples;
};

// The solvers of the threaded rows, on chapter 09's system.
struct ThreadedSolvers {
  const ch09::ThreadsStepper& stepper;
  const SolverSettings& settings;
  ch09::ParallelPcg pcg;
  ch08::PartSetup setup;
  ch08::AssembledProduct product;
  ch09::JacobiOnChunks block_jacobi;
  Eigen::ConjugateGradient<RowMajorMatrix, Eigen::Lower | Eigen::Upper> cg;

  ThreadedSolvers(const ch09::ThreadsStepper& s, const Scene& scene, const SolverSettings& set)
      : stepper(s),
        settings(set),
        pcg(s.system_matrix(), scene.constraints),
        setup{s.scene(), s.model(), s.system(), s.settings()},
        product(setup, {}),
        block_jacobi(setup, {}) {
    cg.setTolerance(settings.tolerance);
    cg.setMaxIterations(settings.max_iterations);
  }

  // The row's solve of the stepper's system (A: Eigen's copy of it) from `guess`, into x.
  void solve(ThreadedRow& row, const RowMajorMatrix& A, const Eigen::VectorXd& guess,
             Eigen::VectorXd& x, bool measured) {
    set_threads(row.threads);
    Eigen::setNbThreads(row.threads);
    const Eigen::VectorXd& b = stepper.system_rhs();
    alloc::Scope scope;
    const auto start = Clock::now();
    int iterations = 0;
    if (row.eigen) {
      cg.compute(A);
      x = cg.solveWithGuess(b, guess);
      iterations = static_cast<int>(cg.iterations());
    } else {
      x = guess;
      iterations =
          pcg.solve(stepper.system_matrix(), product, block_jacobi, b, settings, x).iterations;
    }
    const double ms = ms_between(start, Clock::now());
    const long long allocations = scope.allocations();
    if (!measured) return;
    row.samples.solve.push_back(ms);
    row.samples.iterations.push_back(iterations);
    row.samples.allocations.push_back(static_cast<double>(allocations));
  }
};

void report_progress(const char* table, int k, const Schedule& schedule) {
  if (k > 0 && schedule.reports(k - 1))
    std::cout << "  " << table << ": system " << k << "/" << schedule.total() << "\n" << std::flush;
}

}  // namespace

std::vector<SolverResult> run_solvers(const Scene& scene, const SolverSettings& settings,
                                      const Schedule& schedule) {
  // One thread for these rows: with OpenMP compiled in, Eigen's Lower|Upper CG would use
  // every core (Eigen/src/SparseCore/SparseDenseProduct.h); the threaded rows follow.
  Eigen::setNbThreads(1);
  ch06::CustomPcgStepper stepper(scene, settings);
  State state = rest_state(scene);
  SolveTable table(scene, settings, state.x.size());
  for (int k = 0; k < schedule.total(); ++k) {
    report_progress("solve table", k, schedule);
    stepper.step(state);
    stop_if_interrupted();
    table.solve(stepper.system_matrix(), stepper.system_rhs(), schedule.measured(k));
  }
  return table.results();
}

std::vector<SolverResult> run_threaded_solvers(const Scene& scene, const SolverSettings& settings,
                                               const std::vector<int>& thread_counts,
                                               const Schedule& schedule) {
  std::vector<ThreadedRow> rows;
  for (const bool eigen : {true, false})
    for (const int t : thread_counts)
      rows.push_back(
          {(eigen ? "eigen_cg_rowmajor@" : "pcg_ch09@") + std::to_string(t), t, eigen, {}});
  ch09::ThreadsStepper stepper(scene, settings);
  State state = rest_state(scene);
  ThreadedSolvers solvers(stepper, scene, settings);
  Eigen::VectorXd previous = Eigen::VectorXd::Zero(state.x.size()), x, next;
  for (int k = 0; k < schedule.total(); ++k) {
    report_progress("solve table, threaded rows", k, schedule);
    stepper.step(state);
    stop_if_interrupted();
    const RowMajorMatrix A = stepper.system_matrix().to_sparse();  // not timed
    for (ThreadedRow& row : rows) {
      solvers.solve(row, A, previous, x, schedule.measured(k));
      if (!row.eigen && row.threads == thread_counts.front()) next = x;
    }
    previous = next;
  }
  Eigen::setNbThreads(1);
  std::vector<SolverResult> out;
  for (const ThreadedRow& row : rows) {
    SolverResult r = row.samples.result(row.name);
    r.median_ms = r.solve_ms;  // compute() (a diagonal preconditioner) is timed with the solve
    out.push_back(r);
  }
  return out;
}

}  // namespace fem::bench
