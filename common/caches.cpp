#include "common/caches.hpp"

#include <algorithm>
#include <fstream>
#include <sstream>

namespace fem {
namespace {

std::string read_line(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  return line;
}

// "32K", "1024K", "32M" (sysfs cache sizes) in bytes.
long long size_in_bytes(const std::string& text) {
  if (text.empty()) return 0;
  const long long n = std::stoll(text);
  const char unit = text.back();
  return unit == 'K' ? n << 10 : unit == 'M' ? n << 20 : unit == 'G' ? n << 30 : n;
}

// "0-1,4" (a cpu list) -> 3.
int cpus_in_list(const std::string& list) {
  int count = 0;
  std::istringstream ranges(list);
  std::string range;
  while (std::getline(ranges, range, ',')) {
    const auto dash = range.find('-');
    count += dash == std::string::npos
                 ? 1
                 : std::stoi(range.substr(dash + 1)) - std::stoi(range.substr(0, dash)) + 1;
  }
  return count;
}

}  // namespace

std::vector<CacheLevel> cpu_caches() {
  std::vector<CacheLevel> caches;
  try {
    for (int i = 0;; ++i) {
      const std::string dir = "/sys/devices/system/cpu/cpu0/cache/index" + std::to_string(i) + "/";
      const std::string level = read_line(dir + "level");
      if (level.empty()) break;
      CacheLevel c;
      c.level = std::stoi(level);
      c.type = read_line(dir + "type");
      c.bytes = size_in_bytes(read_line(dir + "size"));
      const std::string shared = read_line(dir + "shared_cpu_list");
      c.shared_by = shared.empty() ? 1 : std::max(1, cpus_in_list(shared));
      caches.push_back(c);
    }
  } catch (const std::exception&) {
    // A kernel that words a field otherwise: the caches read so far stand.
  }
  return caches;
}

std::vector<CacheLevel> data_caches(const std::vector<CacheLevel>& caches) {
  std::vector<CacheLevel> data;
  for (const CacheLevel& c : caches)
    if (c.type != "Instruction" && c.level > 0 && c.bytes > 0) data.push_back(c);
  std::stable_sort(data.begin(), data.end(),
                   [](const CacheLevel& a, const CacheLevel& b) { return a.level < b.level; });
  return data;
}

long long last_cache_bytes() {
  const std::vector<CacheLevel> data = data_caches(cpu_caches());
  return data.empty() ? 0 : data.back().bytes;
}

}  // namespace fem
