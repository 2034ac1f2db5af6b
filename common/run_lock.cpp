#include "common/run_lock.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <ctime>
#include <filesystem>

namespace fem {
namespace {

namespace fs = std::filesystem;

std::string read_holder(int fd) {
  char buffer[512];
  const ssize_t n = ::pread(fd, buffer, sizeof buffer - 1, 0);
  std::string holder(buffer, n > 0 ? static_cast<std::size_t>(n) : 0);
  while (!holder.empty() && (holder.back() == '\n' || holder.back() == ' ')) holder.pop_back();
  return holder;
}

long holder_pid(const std::string& holder) {
  const auto at = holder.find("pid ");
  return at == std::string::npos ? 0 : std::atol(holder.c_str() + at + 4);
}

// The lock is on the file the descriptor holds; a run that released it in between may have
// removed that file's name (~RunLock), and a lock on a removed file locks nothing: the name
// must still be this file.
bool still_named(int fd, const std::string& path) {
  struct stat opened {
  }, named{};
  return ::fstat(fd, &opened) == 0 && ::stat(path.c_str(), &named) == 0 &&
         opened.st_ino == named.st_ino && opened.st_dev == named.st_dev;
}

std::string now() {
  const std::time_t t = std::time(nullptr);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%Y-%m-%d %H:%M:%S", std::localtime(&t));
  return stamp;
}

}  // namespace

RunLock::RunLock(const std::string& folder, const std::string& program, const std::string& name)
    : folder_(folder), path_((fs::path(folder) / name).string()) {
  std::error_code error;
  // The folders this lock makes, deepest first: removed again when the run leaves them empty.
  for (fs::path p = fs::absolute(folder, error); !p.empty() && !fs::exists(p, error);
       p = p.parent_path())
    made_.push_back(p);
  fs::create_directories(folder, error);
  if (error || !fs::is_directory(folder))
    throw std::runtime_error("cannot create the folder '" + folder +
                             "': " + (error ? error.message() : "not a directory"));
  try {
    acquire(program);
  } catch (...) {
    if (fd_ >= 0) ::close(fd_);
    remove_made_folders();
    throw;
  }
}

void RunLock::acquire(const std::string& program) {
  for (;;) {
    fd_ = ::open(path_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd_ < 0)
      throw std::runtime_error("cannot write the lock file '" + path_ +
                               "': " + std::strerror(errno));
    if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
      const std::string holder = read_holder(fd_);
      ::close(fd_);
      fd_ = -1;
      throw FolderInUse("'" + folder_ + "' is in use by another run (" +
                        (holder.empty() ? std::string("lock file ") + path_ : holder) +
                        "): wait for it to end, or give another folder");
    }
    if (still_named(fd_, path_)) break;
    ::close(fd_);  // taken over from a run that has just removed it: again, on the new file
  }
  stale_pid_ = holder_pid(read_holder(fd_));
  const std::string holder =
      program + " pid " + std::to_string(::getpid()) + ", started " + now() + "\n";
  if (::ftruncate(fd_, 0) != 0 || ::pwrite(fd_, holder.data(), holder.size(), 0) < 0)
    throw std::runtime_error("cannot write the lock file '" + path_ + "': " + std::strerror(errno));
}

RunLock::RunLock(RunLock&& other) noexcept
    : folder_(std::move(other.folder_)),
      path_(std::move(other.path_)),
      fd_(other.fd_),
      made_(std::move(other.made_)),
      stale_pid_(other.stale_pid_) {
  other.fd_ = -1;
}

RunLock::~RunLock() {
  if (fd_ < 0) return;
  ::unlink(path_.c_str());  // removed while still locked: no other run can take this file
  ::close(fd_);
  remove_made_folders();
}

void RunLock::remove_made_folders() const {
  std::error_code error;
  for (const fs::path& p : made_)
    if (!fs::is_empty(p, error) || !fs::remove(p, error)) return;
}

}  // namespace fem
