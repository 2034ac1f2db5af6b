// A run is a folder: its bench.json and the plots ./tutorial.sh bench makes of it
// (fem-tools plots bench). The housekeeping around the JSON file.
#pragma once

#include <optional>
#include <string>

#include "apps/bench/options.hpp"
#include "common/run_lock.hpp"

namespace fem::bench {

// Before the work: the JSON's folder exists (or is created) and the file can be written, so
// that a run of minutes does not end in "cannot write". An existing file is left as it is
// until the run is over; a probe file that did not exist is removed again. Throws UsageError.
void check_writable(const std::string& path);

// The run's lock (common/run_lock.hpp): on its folder (--out DIR, or the new folder), or on
// the JSON file's own name beside it for --json FILE (a folder such as results/ holds several
// such files, each another program's). None without JSON. Throws UsageError naming the run
// that holds it.
std::optional<RunLock> lock_run_folder(const BenchOptions& options);

// "'PATH' holds an earlier run: ...": the refusal without --replace; for a directory, a device
// or a FIFO given as --json, what it is (--replace, which that refusal suggests, cannot help
// there, and would replace a device).
std::string holds_a_run(const std::string& json);

// results/latest -> results/FOLDER (a relative symbolic link), the convention for "the newest
// run"; a warning, not an error, where the file system has no links.
void point_latest_at(const std::string& folder);

// Removes the last run's plots from the folder of `json`, so that the folder never shows
// plots of another run; returns how many there were.
int remove_previous_plots(const std::string& json);

}  // namespace fem::bench
