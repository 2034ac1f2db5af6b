// fem_bench's command line: what to measure and where the results go, all checked before the
// run starts, so that a bad option fails at once rather than after minutes of measuring.
#pragma once

#include <string>
#include <vector>

#include "apps/bench/schedule.hpp"
#include "chapters/registry.hpp"
#include "common/cli.hpp"

namespace fem::bench {

struct BenchOptions {
  std::vector<const ChapterInfo*> chapters;
  std::vector<int> thread_counts;  // of the chapters that use threads
  Schedule schedule;
  SolverSettings solver;
  std::string json;         // where the JSON goes; "" for none
  bool json_named = false;  // --json FILE: outside a run folder, whose plots stay
  bool replace = false;     // --replace: an earlier run at the same place may be replaced
  std::string latest;       // the run's folder is a new one under results/: point latest at it
  bool solve_tables = true;
  bool verbose = false;  // --verbose: print what each chapter's stepper builds
};

// The scene's, the solver's and fem_bench's own options.
void add_bench_options(ArgParser& args);

// The options as parsed; throws UsageError with the reason.
BenchOptions bench_options(const ArgParser& args);

}  // namespace fem::bench
