// What a measured ratio depends on, as the kernel reports the machine: the CPU (vendor, family,
// model, model name from /proc/cpuinfo), the instruction set the build targets (the compiler's
// macros) beside the one the CPU offers (its flags), physical cores and hardware threads, the
// cache sizes per level (/sys/devices/system/cpu/cpu0/cache) and the memory (/proc/meminfo).
// Every JSON a program writes carries it ("machine"), so that two runs whose ratios differ can
// be told apart by their records: ./tutorial.sh compare prints what differs.
#pragma once

#include <string>
#include <vector>

#include "common/caches.hpp"
#include "common/json.hpp"

namespace fem {

struct MachineRecord {
  std::string vendor = "unknown", model_name = "unknown";
  int family = -1, model = -1;     // -1: not reported
  std::string isa_build, isa_cpu;  // the widest vector set: SSE2, SSE4.2, AVX, AVX2, AVX-512
  std::vector<std::string> features_build, features_cpu;  // of kVectorFeatures, as cpu flags
  int cores = -1;                                         // physical cores; -1: not reported
  unsigned hardware_threads = 0;
  std::vector<CacheLevel> caches;
  long long memory_bytes = -1;
};

MachineRecord machine_record();
// The record's fields ("vendor": ..., "caches": [...]) added to a JSON object: the writers'
// "machine" object.
void add_machine_record(Json& machine, const MachineRecord& m);
// The same fields as text without the braces, for a writer that assembles its JSON as text.
std::string machine_record_json(const MachineRecord& m);
// For a table's caption: "AVX2 build on an AVX2 CPU (1 core, 2 hardware threads)".
std::string machine_summary(const MachineRecord& m);

}  // namespace fem
