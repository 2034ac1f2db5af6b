// fem_sim: runs a scene with one chapter's stepper and writes VTK frames (a .pvd
// series that ParaView opens).
#include <array>
#include <chrono>
#include <csignal>
#include <iostream>
#include <optional>

#include "chapters/registry.hpp"
#include "common/cli.hpp"
#include "common/deformation.hpp"
#include "common/run_lock.hpp"
#include "common/stepper.hpp"
#include "common/threads.hpp"
#include "common/vtk.hpp"
#include "femcourse/simulator.hpp"

namespace {

using namespace fem;

// Ctrl-C (or a kill) stops the run after the step under way, not in the middle of a write:
// the frames so far are kept and named (VtkSeries::keep_staged), the folder's lock released.
volatile std::sig_atomic_t stop_requested = 0;
extern "C" void request_stop(int) { stop_requested = 1; }

struct Stopped {  // not a std::exception: main() answers it with 130, as a shell does SIGINT
  int steps_done = 0;
};

struct Run {
  const ChapterInfo* chapter = nullptr;
  int steps = 0, every = 0, threads = 1, watch = -1;
  bool threads_asked = false;  // --threads or OMP_NUM_THREADS: every step runs on `threads`
  SolverSettings solver;
};

// The threads the steps ran on, as the stepper's team recorded them step by step.
struct TeamsRan {
  int fewest = 0, most = 0;
  void add(int team) {
    fewest = fewest == 0 ? team : std::min(fewest, team);
    most = std::max(most, team);
  }
  std::string text() const {
    return fewest == most ? std::to_string(most)
                          : std::to_string(fewest) + " to " + std::to_string(most);
  }
};

void add_options(ArgParser& args) {
  add_scene_options(args, "meshes/plate_poster.msh");
  add_solver_options(args);
  add_thread_option(args);
  args.option("chapter", "NAME", "stepper to use (01_naive, 01, naive, ...)", latest_chapter().id);
  args.option("steps", "N", "number of time steps, > 0", "200");
  args.option("every", "N", "write a frame every N steps (0: no output)", "2");
  args.flag("verbose", "print what the stepper built: its recipe's parts and their data");
  args.option("watch", "NODE", "print this node's final position, 17 digits (-1: none)", "-1");
  args.option("out", "DIR",
              "directory for the .vtu frames and the .pvd series (an earlier series of the "
              "scene's name there is replaced once the run ends well, kept if it fails or is "
              "stopped (Ctrl-C: its frames so far in DIR/.SCENE.new); a "
              "folder another run is writing is refused)",
              "out/sim");
}

// Every argument checked before the work; the output folder is checked, not yet made.
Run run_from_args(const ArgParser& args) {
  Run run;
  try {
    run.chapter = &find_chapter(args.get("chapter"));
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  run.steps = args.get_int("steps");
  run.every = args.get_int("every");
  run.watch = args.get_int("watch");
  if (run.watch < -1) throw UsageError("--watch must be a node's index, or -1 for none");
  if (run.steps <= 0) throw UsageError("--steps must be positive");
  if (run.every < 0) throw UsageError("--every must be >= 0");
  run.solver = solver_from_args(args);
  run.threads = threads_from_args(args);
  run.threads_asked = thread_count_asked();
  if (run.every > 0) {
    try {
      VtkSeries::check_writable(args.get("out"));
    } catch (const std::runtime_error& e) {
      throw UsageError(std::string("--out: ") + e.what());
    }
  }
  return run;
}

void print_progress(int k, const Run& run, const Scene& scene, const StepProfile& p) {
  std::cout << "  step " << k << "/" << run.steps << "  t = " << k * scene.dt << " s  step "
            << p.step.seconds * 1e3 << " ms  CG " << p.cg_iterations << " it  residual "
            << p.relative_residual << std::endl;
}

// The steps, with a line every tenth of the run, a frame every `every` steps, and a warning
// for a step that diverged (an error) or that left the body in trouble (common/deformation.hpp).
TeamsRan simulate(const Run& run, femcourse::Body& body, std::optional<VtkSeries>& series) {
  const Scene& scene = body.scene();
  const State& state = body.state();
  if (series) series->write_frame(0.0, scene.mesh.X, scene.mesh.tets, state.x, state.v);
  const DeformationProbe probe(scene);
  DeformationReport deformation;
  const int report_every = std::max(1, run.steps / 10);
  TeamsRan teams;
  for (int k = 1; k <= run.steps; ++k) {
    if (stop_requested) throw Stopped{k - 1};
    const auto start = std::chrono::steady_clock::now();
    try {
      body.step();
    } catch (const femcourse::StepDiverged& e) {
      throw std::runtime_error("the simulation diverged at step " + std::to_string(k) + " (" +
                               e.reason +
                               "); try a smaller --dt, or check --E, --rho, --alpha and --beta");
    }
    teams.add(body.threads_used());
    // The first step allocates the stepper's buffers: the estimate is taken from the second.
    if (k == 2)
      announce_long_run(
          "fem_sim",
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
          run.steps);
    deformation.after_step(k, probe.check(state));
    if (series && k % run.every == 0)
      series->write_frame(k * scene.dt, scene.mesh.X, scene.mesh.tets, state.x, state.v);
    if (k % report_every == 0 || k == run.steps)
      print_progress(k, run, scene, body.stepper().profile());
  }
  deformation.summary(run.steps);
  return teams;
}

// The watched node's position at the end, to every digit: the library's example compares
// its own run of the same body with it (tests/CMakeLists.txt, label library).
void print_watched(const Run& run, const femcourse::Body& body) {
  if (run.watch < 0) return;
  const std::array<double, 3> x = body.position(run.watch);
  std::cout.precision(17);
  std::cout << "node " << run.watch << " at " << x[0] << " " << x[1] << " " << x[2] << "\n";
  std::cout.precision(6);
}

// The output folder is this run's from here to the end (common/run_lock.hpp): a second
// fem_sim into it is refused before any work, rather than each removing the other's frames.
std::optional<RunLock> lock_output(const ArgParser& args, const Run& run) {
  std::optional<RunLock> lock;
  if (run.every == 0) return lock;
  try {
    lock.emplace(args.get("out"), "fem_sim");
  } catch (const FolderInUse& e) {
    throw UsageError(std::string("--out: ") + e.what());
  }
  if (lock->stale_pid() > 0)
    std::cout << "note: " << args.get("out") << " held the lock of a run that is gone (pid "
              << lock->stale_pid() << "); taken over\n";
  return lock;
}

void run_scene(const ArgParser& args, const Run& run) {
  const std::optional<RunLock> lock = lock_output(args, run);
  femcourse::Body body(scene_from_args(args), run.solver, run.chapter->id);
  if (run.threads_asked) body.set_threads(run.threads);  // else the library's choice
  const Scene& scene = body.scene();
  if (run.watch >= scene.mesh.num_nodes())
    throw UsageError("--watch " + std::to_string(run.watch) + ": the mesh has " +
                     std::to_string(scene.mesh.num_nodes()) + " nodes");
  std::cout << "fem_sim: " << scene.name << " on " << scene.mesh.file << " ("
            << scene.mesh.num_nodes() << " nodes, " << scene.mesh.num_tets() << " tets), chapter "
            << run.chapter->id << ", " << run.steps << " steps of " << scene.dt << " s"
            << std::endl;
  const bool threaded = body.stepper().uses_threads();
  std::cout << "threads: "
            << (!threaded           ? "1 (this chapter is single-threaded)"
                : run.threads_asked ? std::to_string(run.threads) + " (asked: every step)"
                                    : "not asked: the library's choice (one thread below " +
                                          std::to_string(femcourse::kSmallBodyNodes) + " nodes)")
            << "\n";
  if (args.has_flag("verbose")) std::cout << "stepper: " << body.stepper();
  // The new series replaces an earlier one only once it is whole (common/vtk.hpp): a run
  // that fails part-way leaves the earlier series as it was.
  std::optional<VtkSeries> series;
  if (run.every > 0) series.emplace(args.get("out"), args.get("scene"));
  const auto start = std::chrono::steady_clock::now();
  std::signal(SIGINT, request_stop);
  std::signal(SIGTERM, request_stop);
  TeamsRan teams;
  try {
    teams = simulate(run, body, series);
  } catch (const Stopped& stopped) {
    std::cout << "fem_sim: stopped after step " << stopped.steps_done << " of " << run.steps;
    if (series)
      std::cout << "; an earlier series in " << args.get("out") << " is as it was, this run's "
                << series->frames() << " frames are in " << series->keep_staged()
                << " (the next run into " << args.get("out") << " removes them)";
    std::cout << std::endl;
    throw;
  } catch (const std::exception& e) {
    if (!series) throw;
    throw std::runtime_error(std::string(e.what()) + "\n(nothing of this run written to " +
                             args.get("out") + ": an earlier series there is as it was)");
  }
  if (series) {
    series->commit();
    if (series->replaced_frames() > 0)
      std::cout << "replaced the earlier series '" << args.get("scene") << "' in "
                << args.get("out") << " (" << series->replaced_frames() << " frames)\n";
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // The team's own record, not the option: what a comparison of thread counts relies on.
  std::cout << "threads the steps ran on: " << teams.text() << "\n";
  std::cout << "done in " << seconds << " s";
  if (series)
    std::cout << "; " << series->frames() << " frames, open " << series->pvd_path()
              << " in ParaView";
  std::cout << "\n";
  print_watched(run, body);
}

}  // namespace

int main(int argc, char** argv) {
  fem::ArgParser args("fem_sim",
                      "Simulates a scene with one chapter's stepper and writes VTK frames.");
  add_options(args);
  return fem::run_program("fem_sim", [&] {
    try {
      if (!args.parse(argc, argv)) return 0;
      run_scene(args, run_from_args(args));
    } catch (const Stopped&) {
      return 130;
    }
    return 0;
  });
}
