#include "apps/bench/report_json.hpp"

#include <filesystem>

#include "common/json.hpp"
#include "common/machine_record.hpp"
#include "common/threads.hpp"

namespace fem::bench {

namespace {

// {"forces": ..., "dfdx": ..., ...}: one number per phase, in StepProfile::phases()' order.
template <class PerPhase>
Json per_phase(const PerPhase& number) {
  Json out = Json::object();
  for (std::size_t i = 0; i < StepProfile::kPhaseCount; ++i)
    out[StepProfile::phases()[i].name] = number(i);
  return out;
}

Json spread_json(const std::array<Spread, StepProfile::kPhaseCount>& ms, double Spread::*field) {
  return per_phase([&](std::size_t i) { return ms[i].*field; });
}

// The run's fields before the tables: the scene, the steps, the solver, the build, the machine.
void add_run(Json& out, const Scene& scene, const BenchOptions& options, const LoadMonitor& load,
             const SourceState& source) {
  const BuildInfo b = build_info();
  out["mesh"] = {{"file", std::filesystem::path(scene.mesh.file).filename().string()},
                 {"nodes", scene.mesh.num_nodes()},
                 {"tets", scene.mesh.num_tets()}};
  out["scene"] = scene.name;
  out["steps"] = options.schedule.steps;
  out["warmup_steps"] = options.schedule.warmup;
  out["dt"] = scene.dt;
  out["material"] = {{"E", scene.material.youngs_modulus},
                     {"nu", scene.material.poisson_ratio},
                     {"rho", scene.material.density},
                     {"alpha", scene.damping.alpha},
                     {"beta", scene.damping.beta}};
  out["cg_tolerance"] = options.solver.tolerance;
  out["cg_max_iterations"] = options.solver.max_iterations;
  out["build"] = {{"compiler", b.compiler},
                  {"flags", b.flags},
                  {"build_type", b.build_type},
                  {"eigen", b.eigen}};
  Json machine = {{"cpu", cpu_model()}, {"threads", hardware_threads()}};
  load.add_json_fields(machine);
  add_machine_record(machine, machine_record());
  out["machine"] = std::move(machine);
  out["openmp"] = openmp_enabled();
  add_source_state(out, source);
}

Json chapter_json(const ChapterResult& r) {
  Json c = {{"chapter", r.chapter}, {"title", r.title}};
  if (!r.variant_of.empty()) c["variant_of"] = r.variant_of;
  c["source_hash"] = r.source_hash;
  c["median_ms"] = spread_json(r.ms, &Spread::median);
  c["min_ms"] = spread_json(r.ms, &Spread::min);
  c["q1_ms"] = spread_json(r.ms, &Spread::q1);
  c["q3_ms"] = spread_json(r.ms, &Spread::q3);
  c["max_ms"] = spread_json(r.ms, &Spread::max);
  c["allocations"] = per_phase([&](std::size_t i) { return r.phase_allocations[i]; });
  c["allocations_per_step"] = r.allocations_per_step;
  c["allocations_max"] = r.allocations_max;
  c["cg_iterations"] = r.cg_iterations;
  c["relative_residual"] = r.relative_residual;
  c["not_converged_steps"] = r.not_converged_steps;
  c["threads"] = r.threads;
  if (r.threads_most > 0) c["threads_ran"] = {r.threads_fewest, r.threads_most};
  return c;
}

Json solver_json(const SolverResult& s) {
  return {{"name", s.name},
          {"median_ms", s.median_ms},
          {"setup_ms", s.setup_ms},
          {"solve_ms", s.solve_ms},
          {"iterations", s.iterations},
          {"allocations_per_solve", s.allocations_per_solve}};
}

}  // namespace

void write_json(const std::string& path, const Scene& scene, const BenchOptions& options,
                const std::vector<ChapterResult>& results, const std::vector<SolverResult>& solvers,
                const LoadMonitor& load, const SourceState& source) {
  Json out = {{"schema_version", 1}};
  Json phases = Json::array();
  for (const StepProfile::Phase& p : StepProfile::phases()) phases.push_back(p.name);
  out["phases"] = std::move(phases);
  add_run(out, scene, options, load, source);
  Json chapters = Json::array();
  for (const ChapterResult& r : results) chapters.push_back(chapter_json(r));
  out["chapters"] = std::move(chapters);
  if (!solvers.empty()) {
    Json table = Json::array();
    for (const SolverResult& s : solvers) table.push_back(solver_json(s));
    out["solvers"] = std::move(table);
  }
  write_json_file(path, out);
}

}  // namespace fem::bench
