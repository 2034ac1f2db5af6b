// fem_bench: measures every chapter on the same scene and mesh, in one process so that the
// ratios between chapters hold while the machine's speed drifts. Prints the per-phase table
// (median ms, allocations per step) and the solve table, and writes them as JSON. One job per
// file: options (the command line), chapter_runs (the interleaved chapters), solve_tables
// (the poster's solve table), report_console and report_json (the results), run_folder (the
// results' folder); the order statistics are common/statistics.hpp's.
#include <csignal>
#include <filesystem>
#include <iostream>
#include <optional>

#include "apps/bench/chapter_runs.hpp"
#include "apps/bench/options.hpp"
#include "apps/bench/report_console.hpp"
#include "apps/bench/report_json.hpp"
#include "apps/bench/run_folder.hpp"
#include "apps/bench/solve_tables.hpp"

using namespace fem;
using namespace fem::bench;

namespace {

std::vector<SolverResult> solve_tables(const Scene& scene, const BenchOptions& options) {
  std::cout << "\nrunning the solve table (every solver on the same systems)\n" << std::flush;
  std::vector<SolverResult> solvers = run_solvers(scene, options.solver, options.schedule);
  for (auto& s :
       run_threaded_solvers(scene, options.solver, options.thread_counts, options.schedule))
    solvers.push_back(std::move(s));
  print_solvers(solvers);
  return solvers;
}

extern "C" void request_stop(int) { interrupted = 1; }

void install_stop_handlers() {
  std::signal(SIGINT, request_stop);
  std::signal(SIGTERM, request_stop);
}

// The measurements and their JSON, after the checks and the lock of run_bench.
int measure_and_write(const ArgParser& args, const BenchOptions& options, bool replacing) {
  const Scene scene = scene_from_args(args);
  // Again after the mesh load: the gmsh reader's initialisation can put SIGTERM back to its
  // default, and a batch system's SIGTERM would then end the run with no word and its lock.
  install_stop_handlers();
  if (!options.json.empty()) check_writable(options.json);
  const SourceState source = source_state();
  print_setup(scene, options, source);
  if (options.verbose)  // what each chapter's stepper builds, before the measured ones
    for (const ChapterInfo* c : options.chapters)
      std::cout << c->id << ": " << *c->make(scene, options.solver);
  LoadMonitor load;
  std::cout << "running " << options.chapters.size() << " chapters interleaved, " << Schedule::turn
            << " steps of each in turn" << std::endl;
  const std::vector<ChapterResult> results = run_chapters(options.chapters, scene, options.solver,
                                                          options.thread_counts, options.schedule);
  print_chapters(results);
  const std::vector<SolverResult> solvers =
      options.solve_tables ? solve_tables(scene, options) : std::vector<SolverResult>{};
  load.stop();
  if (const std::string& path = options.json; !path.empty()) {
    write_json(path, scene, options, results, solvers, load, source);
    // The plots after the JSON: a failed write leaves the earlier run whole, plots and all.
    const int removed = options.json_named ? 0 : remove_previous_plots(path);
    std::cout << "\nwrote " << path
              << (replacing ? " (--replace: replaced the run that was there" : "")
              << (replacing && removed ? ", and its plots" : "") << (replacing ? ")" : "") << "\n";
    if (!options.latest.empty()) point_latest_at(options.latest);
  }
  if (const std::string warning = load.warning(); !warning.empty()) std::cerr << warning << "\n";
  return 0;
}

int run_bench(const ArgParser& args) {
  const BenchOptions options = bench_options(args);
  // The folder is this run's before any work: a second run into it is refused, naming this one.
  const std::optional<RunLock> lock = lock_run_folder(options);
  const bool replacing = !options.json.empty() && std::filesystem::exists(options.json);
  if (replacing && !options.replace) throw UsageError(holds_a_run(options.json));
  install_stop_handlers();
  try {
    return measure_and_write(args, options, replacing);
  } catch (const Interrupted&) {
    std::cout << std::endl;
    std::cerr << "fem_bench: stopped (Ctrl-C or SIGTERM) before the results: nothing of this run "
              << "written"
              << (replacing ? "; the earlier run in " + options.json + " is as it was" : "")
              << std::endl;
    throw;  // the lock released on the way out
  }
}

}  // namespace

int main(int argc, char** argv) {
  ArgParser args("fem_bench",
                 "Benchmarks chapters on one scene: per-phase median ms, allocations per step,\n"
                 "CG iterations; prints a table and writes JSON (schema in README.md) into the\n"
                 "run's folder (--out), where ./tutorial.sh bench also writes the plots.");
  add_bench_options(args);
  try {
    return run_program("fem_bench", [&] { return args.parse(argc, argv) ? run_bench(args) : 0; });
  } catch (const Interrupted&) {
    return 130;
  }
}
