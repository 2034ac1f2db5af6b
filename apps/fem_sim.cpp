// fem_sim: runs a scene with one chapter's stepper and writes VTK frames (a .pvd
// series that ParaView opens).
#include <chrono>
#include <iostream>
#include <optional>

#include "chapters/registry.hpp"
#include "common/cli.hpp"
#include "common/vtk.hpp"

int main(int argc, char** argv) {
  using namespace fem;
  ArgParser args("fem_sim", "Simulates a scene with one chapter's stepper and writes VTK frames.");
  add_scene_options(args, "meshes/plate_poster.msh");
  add_solver_options(args);
  add_thread_option(args);
  args.option("chapter", "NAME", "stepper to use (01_naive, 01, naive, ...)", latest_chapter().id);
  args.option("steps", "N", "number of time steps, > 0", "200");
  args.option("every", "N", "write a frame every N steps (0: no output)", "2");
  args.option("out", "DIR", "directory for the .vtu frames and the .pvd series", "out/sim");
  try {
    if (!args.parse(argc, argv)) return 0;
    const ChapterInfo* found = nullptr;
    try {
      found = &find_chapter(args.get("chapter"));
    } catch (const std::invalid_argument& e) {
      throw UsageError(e.what());
    }
    const ChapterInfo& chapter = *found;
    const int steps = args.get_int("steps");
    const int every = args.get_int("every");
    if (steps <= 0) throw UsageError("--steps must be positive");
    if (every < 0) throw UsageError("--every must be >= 0");
    const SolverSettings solver = solver_from_args(args);
    const int threads = threads_from_args(args);
    // The output folder before the mesh and the steps: a place it cannot write fails at once.
    std::optional<VtkSeries> series;
    if (every > 0) {
      try {
        series.emplace(args.get("out"), args.get("scene"));
      } catch (const std::runtime_error& e) {
        throw UsageError(std::string("--out: ") + e.what());
      }
    }
    const Scene scene = scene_from_args(args);

    std::cout << "fem_sim: " << scene.name << " on " << scene.mesh.file << " ("
              << scene.mesh.num_nodes() << " nodes, " << scene.mesh.num_tets() << " tets), chapter "
              << chapter.id << ", " << steps << " steps of " << scene.dt << " s\n";
    auto stepper = chapter.make(scene, solver);
    std::cout << "threads: " << (stepper->uses_threads() ? threads : 1)
              << (stepper->uses_threads() ? "" : " (this chapter is single-threaded)") << "\n";
    State state = rest_state(scene);
    if (series) series->write_frame(0.0, scene.mesh.X, scene.mesh.tets, state.x, state.v);

    const auto start = std::chrono::steady_clock::now();
    const int report_every = std::max(1, steps / 10);
    for (int k = 1; k <= steps; ++k) {
      stepper->step(state);
      if (const char* why = divergence(state, stepper->profile()))
        throw std::runtime_error("the simulation diverged at step " + std::to_string(k) + " (" +
                                 why +
                                 "); try a smaller --dt, or check --E, --rho, --alpha and --beta");
      if (series && k % every == 0)
        series->write_frame(k * scene.dt, scene.mesh.X, scene.mesh.tets, state.x, state.v);
      if (k % report_every == 0 || k == steps) {
        const StepProfile& p = stepper->profile();
        std::cout << "  step " << k << "/" << steps << "  t = " << k * scene.dt << " s  step "
                  << p.step.seconds * 1e3 << " ms  CG " << p.cg_iterations << " it  residual "
                  << p.relative_residual << "\n";
      }
    }
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::cout << "done in " << seconds << " s";
    if (series)
      std::cout << "; " << series->frames() << " frames, open " << series->pvd_path()
                << " in ParaView";
    std::cout << "\n";
  } catch (const UsageError& e) {
    std::cerr << "fem_sim: " << e.what() << " (see fem_sim --help)\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "fem_sim: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
