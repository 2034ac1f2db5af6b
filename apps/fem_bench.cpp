// fem_bench: measures every chapter on the same scene and mesh, in one process so that
// the ratios between chapters hold while the machine's speed drifts. Prints the
// per-phase table (median ms, allocations per step) and writes it as JSON.
#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCholesky>
#ifdef FEM_HAVE_CHOLMOD
#include <Eigen/CholmodSupport>
#endif
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

#include "chapters/06_custom_pcg/stepper.hpp"
#include "chapters/09_threads/stepper.hpp"
#include "chapters/registry.hpp"
#include "common/alloc_counter.hpp"
#include "common/build_info.hpp"
#include "common/cli.hpp"
#include "common/json.hpp"
#include "common/machine_load.hpp"
#include "common/machine_record.hpp"
#include "common/threads.hpp"

namespace {

using namespace fem;

constexpr std::array<const char*, 6> kPhases = {"forces",      "dfdx",  "compose",
                                                "constraints", "solve", "step"};

std::array<PhaseCost, 6> phases(const StepProfile& p) {
  return {p.forces, p.dfdx, p.compose, p.constraints, p.solve, p.step};
}

// Order statistics of a sample: min, first quartile, median, third quartile, max.
struct Spread {
  double min, q1, median, q3, max;
};

Spread spread(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const auto at = [&v](double q) {  // linear interpolation between order statistics
    const double pos = q * static_cast<double>(v.size() - 1);
    const auto lo = static_cast<std::size_t>(pos);
    const std::size_t hi = std::min(lo + 1, v.size() - 1);
    return v[lo] + (pos - static_cast<double>(lo)) * (v[hi] - v[lo]);
  };
  return {v.front(), at(0.25), at(0.5), at(0.75), v.back()};
}

struct ChapterResult {
  std::string chapter;
  std::string title;
  std::string variant_of;                      // a student's variant: its original
  std::array<Spread, 6> ms;                    // per phase, milliseconds
  double allocations_per_step;                 // median over the measured steps
  std::array<long long, 6> phase_allocations;  // per phase, the last measured step
  long long allocations_max;
  double cg_iterations;      // median
  double relative_residual;  // last step
  int not_converged_steps;
  int threads;  // the thread count of the run: 1 for the single-threaded chapters
};

// One chapter's stepper, state and samples while the benchmark runs.
struct ChapterRun {
  const ChapterInfo* chapter;
  int threads;
  std::unique_ptr<Stepper> stepper;
  State state;
  std::array<std::vector<double>, 6> seconds;
  std::vector<double> allocations, iterations;
  ChapterResult result;
};

// Runs the chapters interleaved, one step of each in turn: when the machine's speed drifts
// (a shared virtual machine, a CPU changing its clock), every chapter sees the same drift,
// so their ratios hold even when the absolute times move.
// A chapter that uses threads (09 on) runs once per thread count, as "09_threads@2".
std::vector<ChapterResult> run_chapters(const std::vector<const ChapterInfo*>& chapters,
                                        const Scene& scene, const SolverSettings& solver,
                                        const std::vector<int>& thread_counts, int warmup,
                                        int steps) {
  std::vector<ChapterRun> runs;
  for (const ChapterInfo* c : chapters) {
    std::unique_ptr<Stepper> first = c->make(scene, solver);
    const bool threaded = first->uses_threads();
    for (const int threads : threaded ? thread_counts : std::vector<int>{1})
      runs.push_back({c,
                      threads,
                      first ? std::move(first) : c->make(scene, solver),
                      rest_state(scene),
                      {},
                      {},
                      {},
                      ChapterResult{threaded ? c->id + "@" + std::to_string(threads) : c->id,
                                    c->title,
                                    c->variant_of,
                                    {},
                                    0.0,
                                    {},
                                    0,
                                    0.0,
                                    0.0,
                                    0,
                                    threads}});
  }
  const int report_every = std::max(1, (warmup + steps) / 5);
  for (int k = 0; k < warmup + steps; ++k) {
    for (ChapterRun& run : runs) {
      set_threads(run.threads);  // the next parallel region's team; no cost between steps
      alloc::Scope counter;
      run.stepper->step(run.state);
      const long long allocs = counter.allocations();
      if (const char* why = divergence(run.state, run.stepper->profile()))
        throw std::runtime_error(run.result.chapter + ": the simulation diverged at step " +
                                 std::to_string(k + 1) + " (" + why + ")");
      if (k < warmup) continue;
      ChapterResult& r = run.result;
      const StepProfile& p = run.stepper->profile();
      const auto s = phases(p);
      for (std::size_t i = 0; i < s.size(); ++i) {
        run.seconds[i].push_back(1e3 * s[i].seconds);
        r.phase_allocations[i] = s[i].allocations;  // deterministic: the last step's
      }
      run.allocations.push_back(static_cast<double>(allocs));
      r.allocations_max = std::max(r.allocations_max, allocs);
      run.iterations.push_back(p.cg_iterations);
      r.relative_residual = p.relative_residual;
      r.not_converged_steps += p.converged ? 0 : 1;
    }
    if ((k + 1) % report_every == 0)
      std::cout << "  step " << k + 1 << "/" << warmup + steps << " of every chapter\n"
                << std::flush;
  }
  std::vector<ChapterResult> results;
  for (ChapterRun& run : runs) {
    ChapterResult& r = run.result;
    for (std::size_t i = 0; i < run.seconds.size(); ++i) r.ms[i] = spread(run.seconds[i]);
    r.allocations_per_step = spread(run.allocations).median;
    r.cg_iterations = spread(run.iterations).median;
    if (r.not_converged_steps > 0)
      std::cout << "  warning: " << r.chapter << ": " << r.not_converged_steps
                << " steps stopped at the CG iteration cap\n";
    results.push_back(r);
  }
  return results;
}

// The poster's solve table, on the same sequence of systems: the filtered systems of a
// run of chapter 06 on the scene. Each solver solves every system from the same inputs;
// "guess" solvers start from the previous system's solution (ours). The pattern never
// changes, so the factorizing solvers analyse it once (analyzePattern, not timed) and
// factorize every step: setup_ms is compute() or factorize(), solve_ms the solve.
struct SolverResult {
  std::string name;
  double median_ms = 0.0, setup_ms = 0.0, solve_ms = 0.0, iterations = 0.0,
         allocations_per_solve = 0.0;
};

std::vector<SolverResult> run_solvers(const Scene& scene, const SolverSettings& settings,
                                      int warmup, int steps) {
  using SparseMatrix = Eigen::SparseMatrix<double>;
  using FullCg = Eigen::ConjugateGradient<SparseMatrix, Eigen::Lower | Eigen::Upper>;
  struct Samples {
    std::vector<double> total, setup, solve, iterations, allocations;
  };
  std::vector<std::string> names = {"eigen_cg",      "eigen_cg_guess",      "pcg_ch06",
                                    "eigen_cg_full", "eigen_cg_full_guess", "eigen_cg_ichol",
                                    "eigen_ldlt"};
#ifdef FEM_HAVE_CHOLMOD
  names.push_back("cholmod_llt");
  Eigen::CholmodSupernodalLLT<SparseMatrix> cholmod;
#endif
  std::vector<Samples> samples(names.size());
  // One thread for these rows: with OpenMP compiled in, Eigen's Lower|Upper CG would use
  // every core (Eigen/src/SparseCore/SparseDenseProduct.h); the threaded rows follow.
  Eigen::setNbThreads(1);
  ch06::CustomPcgStepper stepper(scene, settings);
  State state = rest_state(scene);
  Eigen::VectorXd previous = Eigen::VectorXd::Zero(state.x.size()), x, ours;
  ch06::PcgWorkspace work;
  Eigen::ConjugateGradient<SparseMatrix> cg;
  FullCg cg_full;
  Eigen::ConjugateGradient<SparseMatrix, Eigen::Lower | Eigen::Upper,
                           Eigen::IncompleteCholesky<double>>
      cg_ichol;
  Eigen::SimplicialLDLT<SparseMatrix> ldlt;
  const auto configure = [&settings](auto& solver) {
    solver.setTolerance(settings.tolerance);  // Eigen's default is machine epsilon
    solver.setMaxIterations(settings.max_iterations);
  };
  configure(cg);
  configure(cg_full);
  configure(cg_ichol);
  std::vector<int> offsets;
  const int report_every = std::max(1, (warmup + steps) / 5);
  for (int k = 0; k < warmup + steps; ++k) {
    if (k > 0 && k % report_every == 0)
      std::cout << "  solve table: system " << k << "/" << warmup + steps << "\n" << std::flush;
    stepper.step(state);
    const SparseMatrix& A = stepper.system_matrix();
    const Eigen::VectorXd& b = stepper.system_rhs();
    if (offsets.empty()) {  // the pattern is the same for every system: analyse it once
      offsets = ch06::diagonal_offsets(A);
      cg_ichol.analyzePattern(A);
      ldlt.analyzePattern(A);
#ifdef FEM_HAVE_CHOLMOD
      cholmod.analyzePattern(A);
#endif
    }
    const auto measure = [&](std::size_t i, const std::function<void()>& setup,
                             const std::function<double()>& solve) {
      alloc::Scope scope;
      const auto start = std::chrono::steady_clock::now();
      setup();
      const auto middle = std::chrono::steady_clock::now();
      const double iterations = solve();
      const auto end = std::chrono::steady_clock::now();
      const long long allocations = scope.allocations();
      if (k < warmup) return;
      const auto ms = [](auto a, auto b) {
        return 1e3 * std::chrono::duration<double>(b - a).count();
      };
      samples[i].total.push_back(ms(start, end));
      samples[i].setup.push_back(ms(start, middle));
      samples[i].solve.push_back(ms(middle, end));
      samples[i].iterations.push_back(iterations);
      samples[i].allocations.push_back(static_cast<double>(allocations));
    };
    const auto iterative = [&](auto& solver, bool guess) {
      return [&solver, &b, &previous, &x, guess] {
        if (guess)
          x = solver.solveWithGuess(b, previous);
        else
          x = solver.solve(b);
        if (solver.info() != Eigen::Success && solver.iterations() < solver.maxIterations())
          throw std::runtime_error("the solve table: an Eigen CG failed");
        return static_cast<double>(solver.iterations());
      };
    };
    const auto direct = [&](auto& solver) {
      return [&solver, &b, &x] {
        x = solver.solve(b);
        if (solver.info() != Eigen::Success)
          throw std::runtime_error("the solve table: a direct solver failed");
        return 0.0;
      };
    };
    measure(
        0, [&] { cg.compute(A); }, iterative(cg, false));
    measure(
        1, [&] { cg.compute(A); }, iterative(cg, true));
    measure(
        2, [] {},
        [&] {
          x = previous;
          const double iterations =
              ch06::pcg_solve(A, b, scene.constraints, offsets, settings, work, x).iterations;
          ours = x;
          return iterations;
        });
    measure(
        3, [&] { cg_full.compute(A); }, iterative(cg_full, false));
    measure(
        4, [&] { cg_full.compute(A); }, iterative(cg_full, true));
    measure(
        5, [&] { cg_ichol.factorize(A); }, iterative(cg_ichol, true));
    measure(
        6, [&] { ldlt.factorize(A); }, direct(ldlt));
#ifdef FEM_HAVE_CHOLMOD
    measure(
        7, [&] { cholmod.factorize(A); }, direct(cholmod));
#endif
    previous = ours;  // the next system's guess: this one's solution
  }
  std::vector<SolverResult> out;
  for (std::size_t i = 0; i < names.size(); ++i)
    out.push_back({names[i], spread(samples[i].total).median, spread(samples[i].setup).median,
                   spread(samples[i].solve).median, spread(samples[i].iterations).median,
                   spread(samples[i].allocations).median});
  return out;
}

// The threaded rows of the solve table, on chapter 09's systems (the same filtered systems
// as chapter 06's, assembled in another order): stock Eigen's threaded CG,
// ConjugateGradient<RowMajor, Lower|Upper> with Eigen::setNbThreads(n) (its SpMV is an
// OpenMP loop over rows, sparse_time_dense_product_impl in
// Eigen/src/SparseCore/SparseDenseProduct.h; a column-major matrix with Lower|Upper reaches
// the same loop through its transpose, TransposeInput in ConjugateGradient.h), against chapter 09's
// solver with n OpenMP threads. Both start from the previous system's solution.
std::vector<SolverResult> run_threaded_solvers(const Scene& scene, const SolverSettings& settings,
                                               const std::vector<int>& thread_counts, int warmup,
                                               int steps) {
  using RowMajorMatrix = Eigen::SparseMatrix<double, Eigen::RowMajor>;
  struct Row {
    std::string name;
    int threads;
    bool eigen;
    std::vector<double> ms, iterations, allocations;
  };
  std::vector<Row> rows;
  for (const bool eigen : {true, false})
    for (const int t : thread_counts)
      rows.push_back(
          {(eigen ? "eigen_cg_rowmajor@" : "pcg_ch09@") + std::to_string(t), t, eigen, {}, {}, {}});
  ch09::ThreadsStepper stepper(scene, settings);
  State state = rest_state(scene);
  ch09::ParallelPcg pcg(stepper.system_matrix(), scene.constraints);
  ch09::BlockJacobi block_jacobi(stepper.diagonal_blocks());
  Eigen::ConjugateGradient<RowMajorMatrix, Eigen::Lower | Eigen::Upper> cg;
  cg.setTolerance(settings.tolerance);
  cg.setMaxIterations(settings.max_iterations);
  Eigen::VectorXd previous = Eigen::VectorXd::Zero(state.x.size()), x, next;
  const int report_every = std::max(1, (warmup + steps) / 5);
  for (int k = 0; k < warmup + steps; ++k) {
    if (k > 0 && k % report_every == 0)
      std::cout << "  solve table, threaded rows: system " << k << "/" << warmup + steps << "\n"
                << std::flush;
    stepper.step(state);
    const RowMajorMatrix A = stepper.system_matrix().to_sparse();  // not timed
    const Eigen::VectorXd& b = stepper.system_rhs();
    for (Row& row : rows) {
      set_threads(row.threads);
      Eigen::setNbThreads(row.threads);
      alloc::Scope scope;
      const auto start = std::chrono::steady_clock::now();
      int iterations = 0;
      if (row.eigen) {
        cg.compute(A);
        x = cg.solveWithGuess(b, previous);
        iterations = static_cast<int>(cg.iterations());
      } else {
        x = previous;
        iterations = pcg.solve(stepper.system_matrix(), block_jacobi, b, settings, x).iterations;
      }
      const double ms =
          1e3 * std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      const long long allocations = scope.allocations();
      if (!row.eigen && row.threads == thread_counts.front()) next = x;
      if (k < warmup) continue;
      row.ms.push_back(ms);
      row.iterations.push_back(iterations);
      row.allocations.push_back(static_cast<double>(allocations));
    }
    previous = next;
  }
  Eigen::setNbThreads(1);
  std::vector<SolverResult> out;
  for (const Row& row : rows) {
    SolverResult r;
    r.name = row.name;
    r.median_ms = r.solve_ms = spread(row.ms).median;  // with compute(): a diagonal, microseconds
    r.iterations = spread(row.iterations).median;
    r.allocations_per_solve = spread(row.allocations).median;
    out.push_back(r);
  }
  return out;
}

void print_solvers(const std::vector<SolverResult>& solvers) {
  std::cout << "\nsolve table (the filtered systems of chapter 06's run; same tolerance)\n"
            << std::left << std::setw(21) << "solver" << std::right << std::setw(11) << "median ms"
            << std::setw(10) << "setup" << std::setw(10) << "solve" << std::setw(12) << "iterations"
            << std::setw(14) << "allocs/solve" << std::setw(14) << "vs eigen_cg\n";
  for (const auto& s : solvers)
    std::cout << std::left << std::setw(21) << s.name << std::right << std::fixed
              << std::setprecision(3) << std::setw(11) << s.median_ms << std::setw(10) << s.setup_ms
              << std::setw(10) << s.solve_ms << std::setprecision(0) << std::setw(12)
              << s.iterations << std::setw(14) << s.allocations_per_solve << std::setprecision(2)
              << std::setw(12) << solvers.front().median_ms / s.median_ms << "x"
              << std::defaultfloat << "\n";
  std::cout << "(setup: compute() or factorize() after one analyzePattern; iterations: Eigen counts"
               " the products of full iterations, the last one excluded; pcg_ch06 counts every"
               " product)\n";
  if (solvers.back().name.find('@') != std::string::npos)
    std::cout << "(rows NAME@N: chapter 09's systems, the same filtered systems assembled in "
                 "another order, on N threads)\n";
}

std::string spread_json(const std::array<Spread, 6>& ms, double Spread::*field) {
  std::ostringstream out;
  out << "{";
  for (std::size_t i = 0; i < kPhases.size(); ++i)
    out << (i ? ", " : "") << json_string(kPhases[i]) << ": " << ms[i].*field;
  out << "}";
  return out.str();
}

std::string allocations_json(const std::array<long long, 6>& a) {
  std::ostringstream out;
  out << "{";
  for (std::size_t i = 0; i < kPhases.size(); ++i)
    out << (i ? ", " : "") << json_string(kPhases[i]) << ": " << a[i];
  out << "}";
  return out.str();
}

void write_json(const std::string& path, const Scene& scene, const SolverSettings& solver,
                int warmup, int steps, const std::vector<ChapterResult>& results,
                const std::vector<SolverResult>& solvers, const LoadMonitor& load,
                const SourceState& source) {
  namespace fs = std::filesystem;
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write '" + path + "'");
  const BuildInfo b = build_info();
  out << std::setprecision(10);
  out << "{\n  \"schema_version\": 1,\n";
  out << "  \"mesh\": {\"file\": " << json_string(fs::path(scene.mesh.file).filename().string())
      << ", \"nodes\": " << scene.mesh.num_nodes() << ", \"tets\": " << scene.mesh.num_tets()
      << "},\n";
  out << "  \"scene\": " << json_string(scene.name) << ",\n";
  out << "  \"steps\": " << steps << ",\n  \"warmup_steps\": " << warmup << ",\n";
  out << "  \"dt\": " << scene.dt << ",\n";
  out << "  \"material\": {\"E\": " << scene.material.youngs_modulus
      << ", \"nu\": " << scene.material.poisson_ratio << ", \"rho\": " << scene.material.density
      << ", \"alpha\": " << scene.damping.alpha << ", \"beta\": " << scene.damping.beta << "},\n";
  out << "  \"cg_tolerance\": " << solver.tolerance
      << ",\n  \"cg_max_iterations\": " << solver.max_iterations << ",\n";
  out << "  \"build\": {\"compiler\": " << json_string(b.compiler)
      << ", \"flags\": " << json_string(b.flags)
      << ", \"build_type\": " << json_string(b.build_type)
      << ", \"eigen\": " << json_string(b.eigen) << "},\n";
  out << "  \"machine\": {\"cpu\": " << json_string(cpu_model())
      << ", \"threads\": " << hardware_threads() << ", " << load.json_fields() << ", "
      << machine_record_json(machine_record()) << "},\n";
  out << "  \"openmp\": " << (openmp_enabled() ? "true" : "false") << ",\n";
  out << "  " << source_state_json(source) << ",\n";
  out << "  \"chapters\": [\n";
  for (std::size_t i = 0; i < results.size(); ++i) {
    const ChapterResult& r = results[i];
    out << "    {\"chapter\": " << json_string(r.chapter) << ", \"title\": " << json_string(r.title)
        << (r.variant_of.empty() ? "" : ", \"variant_of\": " + json_string(r.variant_of)) << ",\n"
        << "     \"median_ms\": " << spread_json(r.ms, &Spread::median) << ",\n"
        << "     \"min_ms\": " << spread_json(r.ms, &Spread::min) << ",\n"
        << "     \"q1_ms\": " << spread_json(r.ms, &Spread::q1) << ",\n"
        << "     \"q3_ms\": " << spread_json(r.ms, &Spread::q3) << ",\n"
        << "     \"max_ms\": " << spread_json(r.ms, &Spread::max) << ",\n"
        << "     \"allocations\": " << allocations_json(r.phase_allocations) << ",\n"
        << "     \"allocations_per_step\": " << r.allocations_per_step
        << ", \"allocations_max\": " << r.allocations_max
        << ", \"cg_iterations\": " << r.cg_iterations
        << ", \"relative_residual\": " << r.relative_residual
        << ", \"not_converged_steps\": " << r.not_converged_steps << ", \"threads\": " << r.threads
        << "}" << (i + 1 < results.size() ? "," : "") << "\n";
  }
  out << "  ]";
  if (!solvers.empty()) {
    out << ",\n  \"solvers\": [\n";
    for (std::size_t i = 0; i < solvers.size(); ++i)
      out << "    {\"name\": " << json_string(solvers[i].name)
          << ", \"median_ms\": " << solvers[i].median_ms
          << ", \"setup_ms\": " << solvers[i].setup_ms << ", \"solve_ms\": " << solvers[i].solve_ms
          << ", \"iterations\": " << solvers[i].iterations
          << ", \"allocations_per_solve\": " << solvers[i].allocations_per_solve << "}"
          << (i + 1 < solvers.size() ? "," : "") << "\n";
    out << "  ]";
  }
  out << "\n}\n";
}

void print_table(const std::vector<ChapterResult>& results) {
  std::cout << "\nmedian ms per step (forces = rotations + element forces, common/'s code up to "
               "chapter 07; chapter 08's fused element pass, which also fills A and b, so its dfdx "
               "is 0)\n";
  std::cout << std::left << std::setw(26) << "chapter" << std::right;
  for (const char* p : kPhases) std::cout << std::setw(12) << p;
  std::cout << std::setw(13) << "allocs/step" << std::setw(8) << "CG it" << std::setw(11)
            << "rel.res.\n";
  for (const auto& r : results) {
    std::cout << std::left << std::setw(26) << r.chapter << std::right << std::fixed
              << std::setprecision(3);
    for (const auto& s : r.ms) std::cout << std::setw(12) << s.median;
    std::cout << std::setw(13) << std::setprecision(0) << r.allocations_per_step << std::setw(8)
              << r.cg_iterations << std::setw(10) << std::scientific << std::setprecision(1)
              << r.relative_residual << std::defaultfloat << "\n";
  }
  std::cout << "\nheap allocations per phase (last measured step)\n";
  for (const auto& r : results) {
    std::cout << std::left << std::setw(26) << r.chapter << std::right;
    for (const long long a : r.phase_allocations) std::cout << std::setw(12) << a;
    std::cout << "\n";
  }
  if (results.size() > 1) {
    std::cout << "\nspeedup over " << results.front().chapter << " (median ratio)\n";
    for (const auto& r : results) {
      std::cout << std::left << std::setw(26) << r.chapter << std::right << std::fixed
                << std::setprecision(2);
      for (std::size_t i = 0; i < r.ms.size(); ++i)
        if (r.ms[i].median > 0.0)
          std::cout << std::setw(11) << results.front().ms[i].median / r.ms[i].median << "x";
        else  // a phase the chapter does not have (a fused pass: no df/dx built)
          std::cout << std::setw(12) << "-";
      std::cout << std::defaultfloat << "\n";
    }
  }
}

// "1,2,4" -> {1, 2, 4}; empty -> 1 and OpenMP's count (OMP_NUM_THREADS or every core).
std::vector<int> parse_thread_counts(const std::string& list) {
  std::vector<int> out;
  if (list.empty()) {
    out = {1};
    if (max_threads() > 1) out.push_back(max_threads());
    return out;
  }
  std::stringstream in(list);
  std::string item;
  while (std::getline(in, item, ',')) {
    std::size_t used = 0;
    int n = 0;
    try {
      n = std::stoi(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != item.size() || n < 1)
      throw UsageError("--threads expects thread counts >= 1 separated by commas, got '" + list +
                       "'");
    try {
      if (const std::string warning = check_thread_count(n); !warning.empty())
        std::cerr << "fem_bench: warning: --threads " << item << ": " << warning << "\n";
    } catch (const std::invalid_argument& e) {
      throw UsageError("--threads " + item + ": " + e.what());
    }
    if (std::find(out.begin(), out.end(), n) == out.end()) out.push_back(n);
  }
  return out;
}

std::vector<const ChapterInfo*> parse_chapters(const std::string& list) {
  std::vector<const ChapterInfo*> out;
  if (list == "all") {
    for (const auto& c : chapters()) out.push_back(&c);
    return out;
  }
  std::stringstream in(list);
  std::string name;
  while (std::getline(in, name, ',')) {
    try {
      out.push_back(&find_chapter(name));
    } catch (const std::invalid_argument& e) {
      throw UsageError(e.what());
    }
  }
  if (out.empty()) throw UsageError("--chapters is empty");
  return out;
}

// --json FILE, else DIR/bench.json of --out DIR; "" with --no-json or when both are empty.
std::string json_path(const ArgParser& args) {
  if (args.has_flag("no-json")) {
    if (args.has_flag("json") && !args.get("json").empty())
      throw UsageError("--no-json and --json " + args.get("json") + " contradict each other");
    return "";
  }
  if (!args.get("json").empty()) return args.get("json");
  if (args.get("out").empty()) return "";
  return (std::filesystem::path(args.get("out")) / "bench.json").string();
}

// Before the work: the JSON's folder exists (or is created) and the file can be written, so
// that a run of minutes does not end in "cannot write". An existing file is left as it is
// until the run is over; a probe file that did not exist is removed again.
void check_writable(const std::string& path) {
  namespace fs = std::filesystem;
  const fs::path file(path);
  std::error_code error;
  if (const fs::path dir = file.parent_path(); !dir.empty()) {
    fs::create_directories(dir, error);
    if (error || !fs::is_directory(dir))
      throw UsageError("cannot write the results into '" + dir.string() +
                       "': " + (error ? error.message() : "not a directory"));
  }
  if (fs::is_directory(file)) throw UsageError("'" + path + "' is a directory, not a JSON file");
  const bool existed = fs::exists(file);
  if (!std::ofstream(file, std::ios::app))
    throw UsageError("cannot write '" + path + "' (permissions?)");
  if (!existed) fs::remove(file, error);
}

// The plots ./tutorial.sh bench (scripts/plot_results.py) makes of a run, in its folder: a new
// run there removes the last run's, so that the folder never shows plots of another run.
constexpr std::array<const char*, 4> kRunPlots = {"phases.png", "speedup.png", "allocations.png",
                                                  "solvers.png"};
int remove_previous_plots(const std::string& json) {
  namespace fs = std::filesystem;
  int removed = 0;
  std::error_code error;
  for (const char* name : kRunPlots)
    removed += fs::remove(fs::path(json).parent_path() / name, error) ? 1 : 0;
  return removed;
}

}  // namespace

int main(int argc, char** argv) {
  ArgParser args("fem_bench",
                 "Benchmarks chapters on one scene: per-phase median ms, allocations per step,\n"
                 "CG iterations; prints a table and writes JSON (schema in README.md) into the\n"
                 "run's folder (--out), where ./tutorial.sh bench also writes the plots.");
  add_scene_options(args, "meshes/plate_poster.msh");
  add_solver_options(args);
  args.option("chapters", "LIST", "comma-separated chapters, or 'all'", "all");
  args.option("steps", "N", "measured steps per chapter, > 0", "100");
  args.option("warmup", "N",
              "unmeasured steps first, >= 1 (the first step allocates the stepper's buffers)",
              "10");
  args.option("out", "DIR",
              "the run's folder: writes DIR/bench.json and removes the last run's plots there",
              "results");
  args.option("json", "FILE", "write the JSON here instead of DIR/bench.json", "");
  args.flag("no-json", "write no JSON (print the tables only)");
  args.flag("no-solvers", "skip the solve table (Eigen CG, with guess, ours, IC, LDLT, CHOLMOD)");
  args.option("threads", "LIST",
              "thread counts for the parallel chapters (09 on), comma-separated (default: 1 and "
              "OMP_NUM_THREADS, else 1 and all " +
                  std::to_string(hardware_threads()) + ")",
              "");
  try {
    if (!args.parse(argc, argv)) return 0;
    const auto selected = parse_chapters(args.get("chapters"));
    const int steps = args.get_int("steps"), warmup = args.get_int("warmup");
    if (steps <= 0) throw UsageError("--steps must be positive");
    if (warmup < 1)
      throw UsageError(
          "--warmup must be >= 1: the first step allocates the stepper's buffers, and "
          "the allocations per step are those of the steps after it");
    const SolverSettings solver = solver_from_args(args);
    const std::vector<int> thread_counts = parse_thread_counts(args.get("threads"));
    const std::string path = json_path(args);
    if (!path.empty()) check_writable(path);
    const Scene scene = scene_from_args(args);
    const BuildInfo b = build_info();
    std::cout << "fem_bench: scene " << scene.name << ", mesh " << scene.mesh.file << " ("
              << scene.mesh.num_nodes() << " nodes, " << scene.mesh.num_tets() << " tets), dt "
              << scene.dt << " s, " << warmup << " warm-up + " << steps
              << " measured steps, CG tol " << solver.tolerance << "\n"
              << "build: " << b.compiler << ", " << b.flags << ", Eigen " << b.eigen << "; CPU "
              << cpu_model() << "\n"
              << "threads of the parallel chapters:";
    for (const int t : thread_counts) std::cout << " " << t;
    std::cout << (openmp_enabled() ? "" : " (built without OpenMP)") << "\n";
    const SourceState source = source_state();
    std::cout << "commit " << source.commit;
    if (!source.uncommitted.empty()) {
      std::cout << ", with uncommitted changes in";
      for (const auto& file : source.uncommitted) std::cout << " " << file;
    }
    std::cout << "\n";
    const double others_now = other_cpus_now();
    std::cout << "load average (1 min): " << load_average() << "; other processes use "
              << (others_now < 0 ? std::string("?") : std::to_string(others_now).substr(0, 4))
              << " of " << hardware_threads() << " cores now\n";
    if (others_now > std::max(LoadMonitor::kBusyCores, 0.1 * hardware_threads()))
      std::cout
          << "  note: the machine is busy; the times will show it, threads that wait for each "
             "other at barriers most (the JSON and the plots record it)\n";
    if (!alloc::enabled()) std::cout << "(allocation counting is off in this build)\n";

    LoadMonitor load;
    std::cout << "running " << selected.size() << " chapters interleaved, one step each in turn\n";
    const std::vector<ChapterResult> results =
        run_chapters(selected, scene, solver, thread_counts, warmup, steps);
    print_table(results);
    std::vector<SolverResult> solvers;
    if (!args.has_flag("no-solvers")) {
      std::cout << "\nrunning the solve table (every solver on the same systems)\n" << std::flush;
      solvers = run_solvers(scene, solver, warmup, steps);
      for (auto& s : run_threaded_solvers(scene, solver, thread_counts, warmup, steps))
        solvers.push_back(std::move(s));
      print_solvers(solvers);
    }
    load.stop();
    if (!path.empty()) {
      const bool replaced = std::filesystem::exists(path);
      const int removed = args.get("json").empty() ? remove_previous_plots(path) : 0;
      write_json(path, scene, solver, warmup, steps, results, solvers, load, source);
      std::cout << "\nwrote " << path << (replaced ? " (replacing the run that was there" : "")
                << (replaced && removed ? ", and its plots" : "") << (replaced ? ")" : "") << "\n";
    }
    if (const std::string warning = load.warning(); !warning.empty()) std::cerr << warning << "\n";
  } catch (const UsageError& e) {
    std::cerr << "fem_bench: " << e.what() << " (see fem_bench --help)\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "fem_bench: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
