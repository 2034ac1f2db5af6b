#include "apps/bench/options.hpp"

#include <algorithm>
#include <ctime>
#include <filesystem>
#include <iostream>
#include <sstream>

#include "apps/bench/run_folder.hpp"
#include "common/atomic_file.hpp"
#include "common/build_info.hpp"
#include "common/threads.hpp"

namespace fem::bench {

namespace {

// Without --out, a new folder per run, results/run-YYYYMMDD-HHMMSS (a second run in the same
// second gets -2, -3, ...): a run never replaces an earlier one unless asked (--replace).
std::string new_run_folder() {
  const std::time_t now = std::time(nullptr);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "run-%Y%m%d-%H%M%S", std::localtime(&now));
  std::string folder = std::string("results/") + stamp;
  for (int k = 2; std::filesystem::exists(folder); ++k)
    folder = std::string("results/") + stamp + "-" + std::to_string(k);
  return folder;
}

// --json FILE, else DIR/bench.json of --out DIR; "" with --no-json or when both are empty.
std::string json_path(const ArgParser& args) {
  args.get_nonempty("json");
  args.get_nonempty("out");
  if (args.has_flag("no-json")) {
    if (args.has_flag("json") && !args.get("json").empty())
      throw UsageError("--no-json and --json " + args.get("json") + " contradict each other");
    // --out names the folder of the JSON and its plots: with --no-json it would be ignored.
    if (args.has_flag("out") && !args.get("out").empty())
      throw UsageError("--no-json and --out " + args.get("out") +
                       " contradict each other (--out is the folder of the run's JSON)");
    return "";
  }
  if (!args.get("json").empty()) return args.get("json");
  const std::string out = args.get("out").empty() ? new_run_folder() : args.get("out");
  return (std::filesystem::path(out) / "bench.json").string();
}

Schedule schedule(const ArgParser& args) {
  const int steps = args.get_int("steps"), warmup = args.get_int("warmup");
  const Schedule s{warmup, steps};
  if (s.steps <= 0) throw UsageError("--steps must be positive");
  if (s.warmup < 1)
    throw UsageError(
        "--warmup must be >= 1: the first step allocates the stepper's buffers, and "
        "the allocations per step are those of the steps after it");
  return s;
}

}  // namespace

void add_bench_options(ArgParser& args) {
  add_scene_options(args, "meshes/plate_poster.msh");
  add_solver_options(args);
  args.option("chapters", "LIST",
              "comma-separated chapters, or 'all' (every chapter, variants included)", "all");
  args.option("steps", "N", "measured steps per chapter, > 0", "100");
  args.option("warmup", "N",
              "unmeasured steps first, >= 1 (the first step allocates the stepper's buffers)",
              "10");
  args.option("out", "DIR",
              "the run's folder: writes DIR/bench.json (default: a new folder "
              "results/run-DATE-TIME, and results/latest points to it); a folder that holds a "
              "run is refused unless --replace, a folder another run is writing always",
              "");
  args.flag("replace", "replace the run (bench.json and its plots) in --out DIR or at --json FILE");
  args.option("json", "FILE", "write the JSON here instead of DIR/bench.json", "");
  args.flag("no-json", "write no JSON (print the tables only)");
  args.flag("verbose",
            "print what each chapter's stepper builds: its recipe's parts and their data");
  args.flag("no-solvers", "skip the solve table (Eigen CG, with guess, ours, IC, LDLT, CHOLMOD)");
  args.option("threads", "LIST",
              "thread counts for the parallel chapters (09 on), comma-separated (default: 1 and "
              "OMP_NUM_THREADS, else 1 and all " +
                  std::to_string(hardware_threads()) + ")",
              "");
}

BenchOptions bench_options(const ArgParser& args) {
  BenchOptions o;
  try {
    o.chapters = find_chapters(args.get_list("chapters"));
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("--chapters: ") + e.what());
  }
  o.schedule = schedule(args);
  o.solver = solver_from_args(args);
  o.thread_counts = thread_counts_from_args(args, "threads");
  o.json = json_path(args);
  o.json_named = !args.get("json").empty();
  o.replace = args.has_flag("replace");
  o.verbose = args.has_flag("verbose");
  if (!o.json.empty() && !o.json_named && args.get("out").empty())
    o.latest = std::filesystem::path(o.json).parent_path().filename().string();
  const bool not_a_file = !o.json.empty() && !not_a_regular_file(o.json).empty();
  if (not_a_file || (!o.replace && !o.json.empty() && std::filesystem::exists(o.json)))
    throw UsageError(holds_a_run(o.json));  // a device or a FIFO even with --replace
  o.solve_tables = !args.has_flag("no-solvers");
  return o;
}

}  // namespace fem::bench
