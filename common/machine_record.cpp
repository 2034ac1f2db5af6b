#include "common/machine_record.hpp"

#include <algorithm>
#include <fstream>
#include <set>
#include <sstream>
#include <thread>
#include <utility>

#include "common/json.hpp"

namespace fem {
namespace {

// The vector extensions a ratio between chapters can depend on (chapter 12's lanes, Eigen's
// packet size: Eigen/src/Core/util/ConfigureVectorization.h picks AVX-512, AVX or SSE from
// the same macros), named as /proc/cpuinfo's flags name them, with the macro a compiler
// defines when it targets the extension.
struct Feature {
  const char* flag;
  bool built;
};
constexpr Feature kVectorFeatures[] = {
#ifdef __SSE4_2__
    {"sse4_2", true},
#else
    {"sse4_2", false},
#endif
#ifdef __AVX__
    {"avx", true},
#else
    {"avx", false},
#endif
#ifdef __AVX2__
    {"avx2", true},
#else
    {"avx2", false},
#endif
#ifdef __FMA__
    {"fma", true},
#else
    {"fma", false},
#endif
#ifdef __AVX512F__
    {"avx512f", true},
#else
    {"avx512f", false},
#endif
#ifdef __AVX512VL__
    {"avx512vl", true},
#else
    {"avx512vl", false},
#endif
};

std::string widest(const std::vector<std::string>& features) {
  const std::set<std::string> has(features.begin(), features.end());
  for (const auto& [flag, name] :
       {std::pair{"avx512f", "AVX-512"}, {"avx2", "AVX2"}, {"avx", "AVX"}, {"sse4_2", "SSE4.2"}})
    if (has.count(flag)) return name;
  return "SSE2";
}

std::string value_after_colon(const std::string& line) {
  const auto colon = line.find(':');
  if (colon == std::string::npos) return "";
  const auto start = line.find_first_not_of(" \t", colon + 1);
  return start == std::string::npos ? "" : line.substr(start);
}

bool starts_with(const std::string& line, const std::string& key) {
  return line.rfind(key, 0) == 0 && line.find(':') != std::string::npos &&
         line.find_first_not_of(" \t", key.size()) == line.find(':');
}

// /proc/cpuinfo: the first processor's identity and flags, and the (package, core) pairs of
// all of them, which count the physical cores.
void read_cpuinfo(MachineRecord& m) {
  std::ifstream in("/proc/cpuinfo");
  std::set<std::pair<std::string, std::string>> cores;
  std::string line, package, flags;
  while (std::getline(in, line)) {
    const std::string value = value_after_colon(line);
    if (starts_with(line, "vendor_id") && m.vendor == "unknown") m.vendor = value;
    if (starts_with(line, "cpu family") && m.family < 0) m.family = std::stoi(value);
    if (starts_with(line, "model") && m.model < 0) m.model = std::stoi(value);
    if (starts_with(line, "model name") && m.model_name == "unknown") m.model_name = value;
    if (starts_with(line, "flags") && flags.empty()) flags = " " + value + " ";
    if (starts_with(line, "physical id")) package = value;
    if (starts_with(line, "core id")) cores.insert({package, value});
  }
  for (const Feature& f : kVectorFeatures)
    if (flags.find(" " + std::string(f.flag) + " ") != std::string::npos)
      m.features_cpu.push_back(f.flag);
  if (!cores.empty()) m.cores = static_cast<int>(cores.size());
}

long long memory_bytes() {
  std::ifstream in("/proc/meminfo");
  std::string line;
  while (std::getline(in, line))
    if (starts_with(line, "MemTotal")) return std::stoll(value_after_colon(line)) << 10;  // kB
  return -1;
}

}  // namespace

MachineRecord machine_record() {
  MachineRecord m;
  try {
    read_cpuinfo(m);
    m.caches = cpu_caches();
    m.memory_bytes = memory_bytes();
  } catch (const std::exception&) {
    // A kernel that words a field otherwise leaves it unknown; the record is a note, not input.
  }
  for (const Feature& f : kVectorFeatures)
    if (f.built) m.features_build.push_back(f.flag);
  m.isa_build = widest(m.features_build);
  m.isa_cpu = m.features_cpu.empty() && m.vendor == "unknown" ? "unknown" : widest(m.features_cpu);
  m.hardware_threads = std::thread::hardware_concurrency();
  return m;
}

void add_machine_record(Json& machine, const MachineRecord& m) {
  machine["vendor"] = m.vendor;
  machine["family"] = m.family;
  machine["model"] = m.model;
  machine["model_name"] = m.model_name;
  machine["isa_build"] = m.isa_build;
  machine["isa_cpu"] = m.isa_cpu;
  machine["features_build"] = m.features_build;
  machine["features_cpu"] = m.features_cpu;
  machine["cores"] = m.cores;
  machine["hardware_threads"] = m.hardware_threads;
  Json caches = Json::array();
  for (const CacheLevel& c : m.caches)
    caches.push_back(
        {{"level", c.level}, {"type", c.type}, {"bytes", c.bytes}, {"shared_by", c.shared_by}});
  machine["caches"] = std::move(caches);
  machine["memory_bytes"] = m.memory_bytes;
}

std::string machine_record_json(const MachineRecord& m) {
  Json fields = Json::object();
  add_machine_record(fields, m);
  const std::string text = fields.dump(-1, ' ', false, Json::error_handler_t::replace);
  return text.substr(1, text.size() - 2);  // without the braces
}

std::string machine_summary(const MachineRecord& m) {
  const auto count = [](long long n, const std::string& what) {
    return (n < 0 ? std::string("?") : std::to_string(n)) + " " + what + (n == 1 ? "" : "s");
  };
  return m.isa_build + " build on an " + m.isa_cpu + " CPU (" + count(m.cores, "core") + ", " +
         count(m.hardware_threads, "hardware thread") + ")";
}

}  // namespace fem
