// What fem_bench prints: the run's set-up before the work, then its tables.
#pragma once

#include <vector>

#include "apps/bench/chapter_runs.hpp"
#include "apps/bench/options.hpp"
#include "apps/bench/solve_tables.hpp"
#include "common/build_info.hpp"

namespace fem::bench {

// The scene, the build, the commit and how busy the machine is now.
void print_setup(const Scene& scene, const BenchOptions& options, const SourceState& source);

// Median ms per phase, allocations per phase, and the speedups over the first chapter.
void print_chapters(const std::vector<ChapterResult>& results);

void print_solvers(const std::vector<SolverResult>& solvers);

}  // namespace fem::bench
