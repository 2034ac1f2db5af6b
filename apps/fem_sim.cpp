// fem_sim: runs a scene with one chapter's stepper and writes VTK frames (a .pvd
// series that ParaView opens).
#include <chrono>
#include <iostream>
#include <optional>

#include "chapters/registry.hpp"
#include "common/cli.hpp"
#include "common/vtk.hpp"

using namespace fem;

namespace {

struct SimOptions {
  const ChapterInfo* chapter = nullptr;
  int steps = 0, every = 0;  // every: a frame every `every` steps, 0 for none
  SolverSettings solver;
  int threads = 1;
};

SimOptions sim_options(const ArgParser& args) {
  SimOptions o;
  try {
    o.chapter = &find_chapter(args.get("chapter"));
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  o.steps = args.get_int("steps");
  o.every = args.get_int("every");
  if (o.steps <= 0) throw UsageError("--steps must be positive");
  if (o.every < 0) throw UsageError("--every must be >= 0");
  o.solver = solver_from_args(args);
  o.threads = threads_from_args(args);
  return o;
}

// Opened before the mesh is read and the steps run: a place it cannot write fails at once.
std::optional<VtkSeries> open_series(const ArgParser& args, int every) {
  std::optional<VtkSeries> series;
  if (every > 0) {
    try {
      series.emplace(args.get("out"), args.get("scene"));
    } catch (const std::runtime_error& e) {
      throw UsageError(std::string("--out: ") + e.what());
    }
  }
  return series;
}

// The steps, a frame every `every` of them, a line of progress every tenth of the run.
void simulate(const Scene& scene, const SimOptions& o, Stepper& stepper, State& state,
              std::optional<VtkSeries>& series) {
  const int report_every = std::max(1, o.steps / 10);
  for (int k = 1; k <= o.steps; ++k) {
    stepper.step(state);
    if (const char* why = divergence(state, stepper.profile()))
      throw std::runtime_error("the simulation diverged at step " + std::to_string(k) + " (" + why +
                               "); try a smaller --dt, or check --E, --rho, --alpha and --beta");
    if (series && k % o.every == 0)
      series->write_frame(k * scene.dt, scene.mesh.X, scene.mesh.tets, state.x, state.v);
    if (k % report_every == 0 || k == o.steps) {
      const StepProfile& p = stepper.profile();
      std::cout << "  step " << k << "/" << o.steps << "  t = " << k * scene.dt << " s  step "
                << p.step.seconds * 1e3 << " ms  CG " << p.cg_iterations << " it  residual "
                << p.relative_residual << "\n";
    }
  }
}

int run(const ArgParser& args) {
  const SimOptions o = sim_options(args);
  std::optional<VtkSeries> series = open_series(args, o.every);
  const Scene scene = scene_from_args(args);
  std::cout << "fem_sim: " << scene.name << " on " << scene.mesh.file << " ("
            << scene.mesh.num_nodes() << " nodes, " << scene.mesh.num_tets() << " tets), chapter "
            << o.chapter->id << ", " << o.steps << " steps of " << scene.dt << " s\n";
  auto stepper = o.chapter->make(scene, o.solver);
  std::cout << "threads: " << (stepper->uses_threads() ? o.threads : 1)
            << (stepper->uses_threads() ? "" : " (this chapter is single-threaded)") << "\n";
  State state = rest_state(scene);
  if (series) series->write_frame(0.0, scene.mesh.X, scene.mesh.tets, state.x, state.v);
  const auto start = std::chrono::steady_clock::now();
  simulate(scene, o, *stepper, state, series);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cout << "done in " << seconds << " s";
  if (series)
    std::cout << "; " << series->frames() << " frames, open " << series->pvd_path()
              << " in ParaView";
  std::cout << "\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  ArgParser args("fem_sim", "Simulates a scene with one chapter's stepper and writes VTK frames.");
  add_scene_options(args, "meshes/plate_poster.msh");
  add_solver_options(args);
  add_thread_option(args);
  args.option("chapter", "NAME", "stepper to use (01_naive, 01, naive, ...)", latest_chapter().id);
  args.option("steps", "N", "number of time steps, > 0", "200");
  args.option("every", "N", "write a frame every N steps (0: no output)", "2");
  args.option("out", "DIR", "directory for the .vtu frames and the .pvd series", "out/sim");
  return run_program("fem_sim", [&] { return args.parse(argc, argv) ? run(args) : 0; });
}
