// The caches of the machine as the kernel reports them (/sys/devices/system/cpu/cpu0/cache):
// in the core library, since a stepper can choose a layout by where its data will live
// (chapter 14's finest level), and the course's machine record (machine_record.hpp) reports them.
#pragma once

#include <string>
#include <vector>

namespace fem {

// One cache of cpu0 as the kernel reports it (/sys/devices/system/cpu/cpu0/cache/indexN).
struct CacheLevel {
  int level = 0;
  std::string type;     // Data, Instruction, Unified
  long long bytes = 0;  // per instance
  int shared_by = 1;    // hardware threads sharing one instance
  std::string name() const { return "L" + std::to_string(level); }  // "L1", "L2", ...
};

// The one reader of the caches: every cache of cpu0 in the kernel's index order (data and
// instruction caches both), empty where the system does not say.
std::vector<CacheLevel> cpu_caches();
// The caches data passes through (data and unified, of a known size), innermost first: the
// levels a bandwidth roof is measured for.
std::vector<CacheLevel> data_caches(const std::vector<CacheLevel>& caches);
// The size of one instance of the outermost of them; 0 where the system does not say.
long long last_cache_bytes();

}  // namespace fem
