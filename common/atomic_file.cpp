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

const char* kind_of(fs::file_type type) {
  switch (type) {
    case fs::file_type::directory:
      return "a directory";
    case fs::file_type::character:
      return "a character device";
    case fs::file_type::block:
      return "a block device";
    case fs::file_type::fifo:
      return "a FIFO (named pipe)";
    case fs::file_type::socket:
      return "a socket";
    default:
      return "not a file";
  }
}

}  // namespace

std::string not_a_regular_file(const std::string& path) {
  std::error_code error;
  const fs::file_status status = fs::status(path, error);  // follows links: /dev/stdout
  if (error || !fs::exists(status) || fs::is_regular_file(status)) return "";
  return std::string("it is ") + kind_of(status.type()) +
         ", not a regular file: writing would replace it (or wait for a reader); give a file's "
         "path";
}

void write_file_atomically(const std::string& path, const std::string& text) {
  const fs::path target(path), temporary = temporary_name(target);
  if (const std::string cause = not_a_regular_file(path); !cause.empty())
    throw WriteError("cannot write '" + path + "': " + cause);
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
  if (const std::string cause = not_a_regular_file(path); !cause.empty())
    throw WriteError("cannot write '" + path + "': " + cause);
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
