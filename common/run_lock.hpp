// A run's folder belongs to one run: the run holds an advisory lock on a file in it
// (flock(2) on FOLDER/.fem_run.lock, which names the holder: program and pid), so that a
// second program writing into the same folder is refused before any work, naming the first,
// instead of both leaving a silently mixed folder. The kernel releases the lock when the
// holder exits, however it exits (a crash, SIGKILL): a lock file left behind by a run that is
// gone is stale and is taken over.
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace fem {

// Thrown when another run holds the lock; what() names it and what to do.
struct FolderInUse : std::runtime_error {
  using std::runtime_error::runtime_error;
};

class RunLock {
 public:
  // Locks `folder` (created when missing) for `program`, with the lock file named `name`
  // there (one lock per folder by default; a file written outside any run folder, such as
  // fem_bench --json FILE, locks FILE's own name). Throws FolderInUse when another run
  // holds it, std::runtime_error when the folder cannot be made or the lock file written.
  RunLock(const std::string& folder, const std::string& program,
          const std::string& name = ".fem_run.lock");
  // Removes the lock file, and the folders this lock made that are still empty (a run that
  // failed before its first result leaves no empty folder behind).
  ~RunLock();
  RunLock(RunLock&& other) noexcept;
  RunLock(const RunLock&) = delete;
  RunLock& operator=(const RunLock&) = delete;
  RunLock& operator=(RunLock&&) = delete;

  // The pid of the run whose lock file was found stale (its process gone), 0 for none.
  long stale_pid() const { return stale_pid_; }

 private:
  void acquire(const std::string& program);
  void remove_made_folders() const;

  std::string folder_, path_;
  int fd_ = -1;
  std::vector<std::filesystem::path> made_;
  long stale_pid_ = 0;
};

}  // namespace fem
