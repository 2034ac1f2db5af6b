// The run as JSON (the schema in README.md, checked by fem-tools results validate): what was
// measured, on what, and the chapter and solve tables.
#pragma once

#include <string>
#include <vector>

#include "apps/bench/chapter_runs.hpp"
#include "apps/bench/options.hpp"
#include "apps/bench/solve_tables.hpp"
#include "common/build_info.hpp"
#include "common/machine_load.hpp"

namespace fem::bench {

// Throws std::runtime_error when the file cannot be written.
void write_json(const std::string& path, const Scene& scene, const BenchOptions& options,
                const std::vector<ChapterResult>& results, const std::vector<SolverResult>& solvers,
                const LoadMonitor& load, const SourceState& source);

}  // namespace fem::bench
