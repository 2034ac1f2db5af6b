#include "apps/bench/options.hpp"

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <sstream>

#include "common/build_info.hpp"
#include "common/threads.hpp"

namespace fem::bench {

namespace {

// "1,2,4" -> {1, 2, 4}; empty -> 1 and OpenMP's count (OMP_NUM_THREADS or every core).
std::vector<int> parse_thread_counts(const std::string& list) {
  if (list.empty()) {
    std::vector<int> out = {1};
    if (max_threads() > 1) out.push_back(max_threads());
    return out;
  }
  std::vector<int> out;
  std::stringstream in(list);
  std::string item;
  while (std::getline(in, item, ',')) {
    const std::optional<int> parsed = parse_int(item);
    if (!parsed || *parsed < 1)
      throw UsageError("--threads expects thread counts >= 1 separated by commas, got '" + list +
                       "'");
    const int n = *parsed;
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
}

BenchOptions bench_options(const ArgParser& args) {
  BenchOptions o;
  o.chapters = parse_chapters(args.get("chapters"));
  o.schedule = schedule(args);
  o.solver = solver_from_args(args);
  o.thread_counts = parse_thread_counts(args.get("threads"));
  o.json = json_path(args);
  o.json_named = !args.get("json").empty();
  o.solve_tables = !args.has_flag("no-solvers");
  return o;
}

}  // namespace fem::bench
