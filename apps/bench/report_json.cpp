#include "apps/bench/report_json.hpp"

#include <filesystem>
#include <iomanip>
#include <sstream>

#include "common/atomic_file.hpp"
#include "common/json.hpp"
#include "common/machine_record.hpp"
#include "common/threads.hpp"

namespace fem::bench {

namespace {

// {"forces": ..., "dfdx": ..., ...}: one number per phase.
template <class PerPhase>
std::string phases_json(const PerPhase& number) {
  std::ostringstream out;
  out << "{";
  for (std::size_t i = 0; i < kPhases.size(); ++i)
    out << (i ? ", " : "") << json_string(kPhases[i]) << ": " << number(i);
  out << "}";
  return out.str();
}

std::string spread_json(const std::array<Spread, 6>& ms, double Spread::*field) {
  return phases_json([&](std::size_t i) { return ms[i].*field; });
}

// The run's fields before the tables: the scene, the steps, the solver, the build, the machine.
void write_run(std::ostream& out, const Scene& scene, const BenchOptions& options,
               const LoadMonitor& load, const SourceState& source) {
  const BuildInfo b = build_info();
  out << "  \"mesh\": {\"file\": "
      << json_string(std::filesystem::path(scene.mesh.file).filename().string())
      << ", \"nodes\": " << scene.mesh.num_nodes() << ", \"tets\": " << scene.mesh.num_tets()
      << "},\n";
  out << "  \"scene\": " << json_string(scene.name) << ",\n";
  out << "  \"steps\": " << options.schedule.steps
      << ",\n  \"warmup_steps\": " << options.schedule.warmup << ",\n";
  out << "  \"dt\": " << scene.dt << ",\n";
  out << "  \"material\": {\"E\": " << scene.material.youngs_modulus
      << ", \"nu\": " << scene.material.poisson_ratio << ", \"rho\": " << scene.material.density
      << ", \"alpha\": " << scene.damping.alpha << ", \"beta\": " << scene.damping.beta << "},\n";
  out << "  \"cg_tolerance\": " << options.solver.tolerance
      << ",\n  \"cg_max_iterations\": " << options.solver.max_iterations << ",\n";
  out << "  \"build\": {\"compiler\": " << json_string(b.compiler)
      << ", \"flags\": " << json_string(b.flags)
      << ", \"build_type\": " << json_string(b.build_type)
      << ", \"eigen\": " << json_string(b.eigen) << "},\n";
  out << "  \"machine\": {\"cpu\": " << json_string(cpu_model())
      << ", \"threads\": " << hardware_threads() << ", " << load.json_fields() << ", "
      << machine_record_json(machine_record()) << "},\n";
  out << "  \"openmp\": " << (openmp_enabled() ? "true" : "false") << ",\n";
  out << "  " << source_state_json(source) << ",\n";
}

void write_chapter(std::ostream& out, const ChapterResult& r) {
  out << "    {\"chapter\": " << json_string(r.chapter) << ", \"title\": " << json_string(r.title)
      << (r.variant_of.empty() ? "" : ", \"variant_of\": " + json_string(r.variant_of))
      << ", \"source_hash\": " << json_string(r.source_hash) << ",\n"
      << "     \"median_ms\": " << spread_json(r.ms, &Spread::median) << ",\n"
      << "     \"min_ms\": " << spread_json(r.ms, &Spread::min) << ",\n"
      << "     \"q1_ms\": " << spread_json(r.ms, &Spread::q1) << ",\n"
      << "     \"q3_ms\": " << spread_json(r.ms, &Spread::q3) << ",\n"
      << "     \"max_ms\": " << spread_json(r.ms, &Spread::max) << ",\n"
      << "     \"allocations\": "
      << phases_json([&](std::size_t i) { return r.phase_allocations[i]; }) << ",\n"
      << "     \"allocations_per_step\": " << r.allocations_per_step
      << ", \"allocations_max\": " << r.allocations_max
      << ", \"cg_iterations\": " << r.cg_iterations
      << ", \"relative_residual\": " << r.relative_residual
      << ", \"not_converged_steps\": " << r.not_converged_steps << ", \"threads\": " << r.threads
      << "}";
}

void write_solver(std::ostream& out, const SolverResult& s) {
  out << "    {\"name\": " << json_string(s.name) << ", \"median_ms\": " << s.median_ms
      << ", \"setup_ms\": " << s.setup_ms << ", \"solve_ms\": " << s.solve_ms
      << ", \"iterations\": " << s.iterations
      << ", \"allocations_per_solve\": " << s.allocations_per_solve << "}";
}

void write_document(std::ostream& out, const Scene& scene, const BenchOptions& options,
                    const std::vector<ChapterResult>& results,
                    const std::vector<SolverResult>& solvers, const LoadMonitor& load,
                    const SourceState& source) {
  out << std::setprecision(10);
  out << "{\n  \"schema_version\": 1,\n";
  write_run(out, scene, options, load, source);
  out << "  \"chapters\": [\n";
  for (std::size_t i = 0; i < results.size(); ++i) {
    write_chapter(out, results[i]);
    out << (i + 1 < results.size() ? "," : "") << "\n";
  }
  out << "  ]";
  if (!solvers.empty()) {
    out << ",\n  \"solvers\": [\n";
    for (std::size_t i = 0; i < solvers.size(); ++i) {
      write_solver(out, solvers[i]);
      out << (i + 1 < solvers.size() ? "," : "") << "\n";
    }
    out << "  ]";
  }
  out << "\n}\n";
}

}  // namespace

void write_json(const std::string& path, const Scene& scene, const BenchOptions& options,
                const std::vector<ChapterResult>& results, const std::vector<SolverResult>& solvers,
                const LoadMonitor& load, const SourceState& source) {
  write_file_atomically(path, [&](std::ostream& out) {
    write_document(out, scene, options, results, solvers, load, source);
  });
}

}  // namespace fem::bench
