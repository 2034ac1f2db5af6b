#include "apps/bench/report_console.hpp"

#include <iomanip>
#include <iostream>

#include "common/alloc_counter.hpp"
#include "common/machine_load.hpp"
#include "common/threads.hpp"

namespace fem::bench {

namespace {

void print_load() {
  const double others_now = other_cpus_now();
  std::cout << "load average (1 min): " << load_average() << "; other processes use "
            << (others_now < 0 ? std::string("?") : std::to_string(others_now).substr(0, 4))
            << " of " << hardware_threads() << " cores now\n";
  if (others_now > std::max(LoadMonitor::kBusyCores, 0.1 * hardware_threads()))
    std::cout << "  note: the machine is busy; the times will show it, threads that wait for each "
                 "other at barriers most (the JSON and the plots record it)\n";
}

void print_speedups(const std::vector<ChapterResult>& results) {
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

}  // namespace

void print_setup(const Scene& scene, const BenchOptions& options, const SourceState& source) {
  const BuildInfo b = build_info();
  std::cout << "fem_bench: scene " << scene.name << ", mesh " << scene.mesh.file << " ("
            << scene.mesh.num_nodes() << " nodes, " << scene.mesh.num_tets() << " tets), dt "
            << scene.dt << " s, " << options.schedule.warmup << " warm-up + "
            << options.schedule.steps << " measured steps, CG tol " << options.solver.tolerance
            << "\n"
            << "build: " << b.compiler << ", " << b.flags << ", Eigen " << b.eigen << "; CPU "
            << cpu_model() << "\n"
            << "threads of the parallel chapters:";
  for (const int t : options.thread_counts) std::cout << " " << t;
  std::cout << (openmp_enabled() ? "" : " (built without OpenMP)") << "\n";
  std::cout << "commit " << source.commit;
  if (!source.uncommitted.empty()) {
    std::cout << ", with uncommitted changes in";
    for (const auto& file : source.uncommitted) std::cout << " " << file;
  }
  std::cout << "\n";
  print_load();
  if (!alloc::enabled()) std::cout << "(allocation counting is off in this build)\n";
}

void print_chapters(const std::vector<ChapterResult>& results) {
  std::cout << "\nmedian ms per step (forces = rotations + element forces, common/'s code up to "
               "chapter 07; chapter 08's fused element pass, which also fills A and b, so its dfdx "
               "is 0)\n";
  std::cout << std::left << std::setw(26) << "chapter" << std::right;
  for (const StepProfile::Phase& p : StepProfile::phases()) std::cout << std::setw(12) << p.name;
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
  if (results.size() > 1) print_speedups(results);
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

}  // namespace fem::bench
