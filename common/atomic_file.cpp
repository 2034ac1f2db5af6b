#include "common/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <sstream>

namespace fem {
namespace {

namespace fs = std::filesystem;

bool failure_injected(const fs::path& path) {
  const char* name = std::getenv("FEM_FAIL_WRITES");
  return name && (std::string(name) == "*" || path.filename() == name);
}

// write(2) until all is written: the system's own error (ENOSPC, EDQUOT, EIO) in errno,
// which an std::ofstream does not keep.
bool write_all(int fd, const std::string& text, bool fail_half_way) {
  const std::size_t size = fail_half_way ? text.size() / 2 : text.size();
  for (std::size_t done = 0; done < size;) {
    const ssize_t n = ::write(fd, text.data() + done, size - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    done += static_cast<std::size_t>(n);
  }
  if (fail_half_way) errno = ENOSPC;
  return !fail_half_way;
}

// The temporary name: hidden, in the same folder (rename(2) does not cross file systems),
// and the process's own (two programs never share one).
fs::path temporary_name(const fs::path& path) {
  return path.parent_path() /
         ("." + path.filename().string() + ".tmp" + std::to_string(::getpid()));
}

}  // namespace

void write_file_atomically(const std::string& path, const std::string& text) {
  const fs::path target(path), temporary = temporary_name(target);
  const auto fail = [&](int cause) {
    ::unlink(temporary.c_str());
    throw WriteError("cannot write '" + path + "': " + std::strerror(cause));
  };
  const int fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw WriteError("cannot write '" + path + "': " + std::strerror(errno));
  // fsync before the rename: otherwise a crash right after it can leave the new name on an
  // empty file (ext4's delayed allocation).
  if (!write_all(fd, text, failure_injected(target)) || ::fsync(fd) != 0) {
    const int cause = errno;
    ::close(fd);
    fail(cause);
  }
  if (::close(fd) != 0) fail(errno);
  if (::rename(temporary.c_str(), target.c_str()) != 0) fail(errno);
}

void check_writable(const std::string& path) {
  const fs::path target(path);
  std::error_code error;
  if (fs::is_directory(target, error))
    throw WriteError("cannot write '" + path + "': it is a directory");
  const fs::path temporary = temporary_name(target);
  const int fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) throw WriteError("cannot write '" + path + "': " + std::strerror(errno));
  ::close(fd);
  ::unlink(temporary.c_str());
}

void write_file_atomically(const std::string& path,
                           const std::function<void(std::ostream&)>& write) {
  std::ostringstream text;
  write(text);
  write_file_atomically(path, text.str());
}

}  // namespace fem
