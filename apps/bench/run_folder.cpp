#include "apps/bench/run_folder.hpp"

#include <array>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "common/atomic_file.hpp"
#include "common/cli.hpp"

namespace fem::bench {

namespace fs = std::filesystem;

void check_writable(const std::string& path) {
  const fs::path file(path);
  std::error_code error;
  if (const fs::path dir = file.parent_path(); !dir.empty()) {
    fs::create_directories(dir, error);
    if (error || !fs::is_directory(dir))
      throw UsageError("cannot write the results into '" + dir.string() +
                       "': " + (error ? error.message() : "not a directory"));
  }
  // A device or a FIFO: refused before the open below, which would replace or block on it.
  if (!not_a_regular_file(path).empty()) throw UsageError(holds_a_run(path));
  const bool existed = fs::exists(file);
  if (!std::ofstream(file, std::ios::app))
    throw UsageError("cannot write '" + path + "' (permissions?)");
  if (!existed) fs::remove(file, error);
}

std::optional<RunLock> lock_run_folder(const BenchOptions& options) {
  std::optional<RunLock> lock;
  if (options.json.empty()) return lock;
  const fs::path json(options.json);
  const std::string folder = json.parent_path().empty() ? "." : json.parent_path().string();
  try {
    if (options.json_named)
      lock.emplace(folder, "fem_bench", "." + json.filename().string() + ".lock");
    else
      lock.emplace(folder, "fem_bench");
  } catch (const FolderInUse& e) {
    throw UsageError(e.what());
  } catch (const std::runtime_error& e) {
    throw UsageError(std::string("cannot write the results: ") + e.what());
  }
  if (lock->stale_pid() > 0)
    std::cout << "note: " << folder << " held the lock of a run that is gone (pid "
              << lock->stale_pid() << "); taken over\n";
  return lock;
}

std::string holds_a_run(const std::string& json) {
  if (fs::is_directory(json))
    return "'" + json + "' is a directory, not a JSON file: give a file (--json " +
           (fs::path(json) / "bench.json").string() + "), or the folder as --out " + json;
  // A device or a FIFO holds no run, and --replace would replace the node itself.
  if (const std::string cause = not_a_regular_file(json); !cause.empty())
    return "--json '" + json + "': " + cause + ", or --no-json to print the tables only";
  return "'" + json +
         "' holds an earlier run: give another --out (or --json), or --replace to replace it "
         "and its plots";
}

void point_latest_at(const std::string& folder) {
  const fs::path link = fs::path("results") / "latest";
  std::error_code error;
  if (fs::is_symlink(link, error) || !fs::exists(link, error)) fs::remove(link, error);
  fs::create_directory_symlink(folder, link, error);
  if (error)
    std::cerr << "fem_bench: warning: cannot point " << link.string() << " at " << folder << ": "
              << error.message() << "\n";
  else
    std::cout << "results/latest -> " << folder << "\n";
}

int remove_previous_plots(const std::string& json) {
  // The plots fem-tools plots bench makes of a run.
  constexpr std::array<const char*, 5> kRunPlots = {
      "phases.png", "phases_stacked.png", "speedup.png", "allocations.png", "solvers.png"};
  int removed = 0;
  std::error_code error;
  for (const char* name : kRunPlots)
    removed += fs::remove(fs::path(json).parent_path() / name, error) ? 1 : 0;
  return removed;
}

}  // namespace fem::bench
