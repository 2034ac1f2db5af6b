// A run is a folder: its bench.json and the plots ./tutorial.sh bench makes of it
// (fem-tools plots bench). The housekeeping around the JSON file.
#pragma once

#include <string>

namespace fem::bench {

// Before the work: the JSON's folder exists (or is created) and the file can be written, so
// that a run of minutes does not end in "cannot write". An existing file is left as it is
// until the run is over; a probe file that did not exist is removed again. Throws UsageError.
void check_writable(const std::string& path);

// results/latest -> results/FOLDER (a relative symbolic link), the convention for "the newest
// run"; a warning, not an error, where the file system has no links.
void point_latest_at(const std::string& folder);

// Removes the last run's plots from the folder of `json`, so that the folder never shows
// plots of another run; returns how many there were.
int remove_previous_plots(const std::string& json);

}  // namespace fem::bench
