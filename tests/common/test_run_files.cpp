// A run's folder and files: the lock that makes a folder one run's (common/run_lock.hpp) and
// results written whole or not at all (common/atomic_file.hpp).
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "catch2_compat.hpp"
#include "common/atomic_file.hpp"
#include "common/run_lock.hpp"

using namespace fem;
namespace fs = std::filesystem;

namespace {

std::string read(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

fs::path fresh_folder(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / (name + std::to_string(::getpid()));
  fs::remove_all(dir);
  return dir;
}

// FEM_FAIL_WRITES for a scope: the failure common/atomic_file.hpp injects.
struct FailWrites {
  explicit FailWrites(const char* name) { ::setenv("FEM_FAIL_WRITES", name, 1); }
  ~FailWrites() { ::unsetenv("FEM_FAIL_WRITES"); }
};

}  // namespace

TEST_CASE("run lock: a second run into a locked folder is refused, naming the first", "[run]") {
  const fs::path dir = fresh_folder("fem_test_lock");
  {
    const RunLock first(dir.string(), "fem_sim");
    CHECK(fs::exists(dir / ".fem_run.lock"));
    CHECK_THROWS_AS(RunLock(dir.string(), "fem_bench"), FolderInUse);
    CHECK_THROWS_WITH(RunLock(dir.string(), "fem_bench"),
                      test::contains_text("fem_sim pid " + std::to_string(::getpid())));
    // Another file's lock in the same folder is another lock (fem_bench --json FILE).
    const RunLock other(dir.string(), "fem_bench", ".bench.json.lock");
    CHECK(fs::exists(dir / ".bench.json.lock"));
  }
  // Released: the lock files are gone, and so is the folder the first lock made (empty).
  CHECK_FALSE(fs::exists(dir));
  const RunLock again(dir.string(), "fem_bench");
  CHECK(again.stale_pid() == 0);
  // Nested folders the lock made are all removed again when the run leaves them empty.
  { const RunLock nested((dir / "a" / "b").string(), "fem_sim"); }
  CHECK(fs::is_directory(dir));
  CHECK_FALSE(fs::exists(dir / "a"));
}

TEST_CASE("run lock: a lock file whose run is gone is stale and taken over", "[run]") {
  const fs::path dir = fresh_folder("fem_test_stale_lock");
  fs::create_directories(dir);
  std::ofstream(dir / ".fem_run.lock") << "fem_sim pid 999999, started 2026-01-01 00:00:00\n";
  {
    const RunLock lock(dir.string(), "fem_sim");
    CHECK(lock.stale_pid() == 999999);
    CHECK_THAT(read(dir / ".fem_run.lock"),
               test::contains_text("fem_sim pid " + std::to_string(::getpid())));
  }
  // The folder existed before the lock: it stays, without the lock file.
  CHECK(fs::is_directory(dir));
  CHECK(fs::is_empty(dir));
  fs::remove_all(dir);
}

TEST_CASE("atomic write: the whole file, and no temporary left", "[run]") {
  const fs::path dir = fresh_folder("fem_test_atomic");
  fs::create_directories(dir);
  write_file_atomically((dir / "a.json").string(), "{\"old\": 1}\n");
  write_file_atomically((dir / "a.json").string(),
                        [](std::ostream& out) { out << "{\"new\": " << 2 << "}\n"; });
  CHECK(read(dir / "a.json") == "{\"new\": 2}\n");
  CHECK(std::distance(fs::directory_iterator(dir), fs::directory_iterator()) == 1);
  fs::remove_all(dir);
}

TEST_CASE("atomic write: a write that fails half-way leaves the earlier file as it was", "[run]") {
  const fs::path dir = fresh_folder("fem_test_atomic_fail");
  fs::create_directories(dir);
  const std::string earlier = "{\"earlier\": \"a good run\"}\n";
  write_file_atomically((dir / "bench.json").string(), earlier);
  {
    const FailWrites full_disk("bench.json");
    CHECK_THROWS_AS(write_file_atomically((dir / "bench.json").string(), std::string(9000, 'x')),
                    WriteError);
    CHECK_THROWS_WITH(write_file_atomically((dir / "bench.json").string(), "{}"),
                      test::contains_text((dir / "bench.json").string() + "': No space left"));
    // Another file's write is not the one that fails.
    write_file_atomically((dir / "other.json").string(), "{}");
  }
  CHECK(read(dir / "bench.json") == earlier);
  CHECK(std::distance(fs::directory_iterator(dir), fs::directory_iterator()) == 2);
  // A folder that cannot be written: the path and the system's cause.
  CHECK_THROWS_WITH(write_file_atomically("/proc/fem_no_such/a.json", "{}"),
                    test::contains_text("cannot write '/proc/fem_no_such/a.json': "));
  fs::remove_all(dir);
}
