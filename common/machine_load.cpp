#include "common/machine_load.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <thread>

#include "common/build_info.hpp"

namespace fem {
namespace {

// Seconds of CPU time the whole machine has been busy since boot, -1 where unknown.
double machine_busy_seconds() {
  std::ifstream in("/proc/stat");
  std::string cpu;
  unsigned long long user = 0, nice = 0, system = 0, idle = 0, iowait = 0, irq = 0, softirq = 0,
                     steal = 0;
  if (!(in >> cpu >> user >> nice >> system >> idle >> iowait >> irq >> softirq) || cpu != "cpu")
    return -1.0;
  in >> steal;  // absent on old kernels: 0
  const long ticks = sysconf(_SC_CLK_TCK);
  if (ticks <= 0) return -1.0;
  // guest time is already inside user (proc(5)); idle and iowait are not busy.
  return static_cast<double>(user + nice + system + irq + softirq + steal) /
         static_cast<double>(ticks);
}

// Seconds of CPU time this process has used, all its threads, and the children it has waited
// for: a measurement's own load (fem_lessons frame-times spins a child on one core) is not
// another process's.
double self_seconds() {
  const auto seconds = [](const timeval& t) { return t.tv_sec + 1e-6 * t.tv_usec; };
  double total = 0.0;
  for (const int who : {RUSAGE_SELF, RUSAGE_CHILDREN}) {
    rusage usage{};
    if (getrusage(who, &usage) == 0) total += seconds(usage.ru_utime) + seconds(usage.ru_stime);
  }
  return total;
}

double wall_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

std::string number(double v) {
  std::ostringstream out;
  out.precision(3);
  out << v;
  return out.str();
}

}  // namespace

double load_average() {
  std::ifstream in("/proc/loadavg");
  double load = -1.0;
  return (in >> load) ? load : -1.0;
}

LoadMonitor::LoadMonitor()
    : load_before_(load_average()),
      machine_start_(machine_busy_seconds()),
      self_start_(self_seconds()),
      wall_start_(wall_seconds()),
      cores_(std::max(1u, hardware_threads())) {}

void LoadMonitor::stop() {
  if (stopped_) return;
  stopped_ = true;
  load_after_ = load_average();
  const double machine = machine_busy_seconds(), wall = wall_seconds() - wall_start_;
  if (machine < 0.0 || machine_start_ < 0.0 || wall <= 0.0) return;
  const double others = (machine - machine_start_) - (self_seconds() - self_start_);
  other_cpus_ = std::max(0.0, others / wall);
}

bool LoadMonitor::busy() const { return other_cpus_ > std::max(kBusyCores, 0.1 * cores_); }

std::string LoadMonitor::warning() const {
  if (!busy()) return "";
  return "warning: the machine was busy: other processes used " + number(other_cpus_) + " of its " +
         std::to_string(cores_) + " cores on average while this ran (1-minute load average " +
         number(load_before_) + " before, " + number(load_after_) +
         " after); its times are not the code's alone, rerun on a quiet machine";
}

void LoadMonitor::add_json_fields(Json& machine) const {
  machine["load_average"] = {load_before_, load_after_};
  machine["other_cpus"] = other_cpus_ < 0.0 ? Json() : Json(other_cpus_);
  machine["busy"] = busy();
}

double other_cpus_now(double seconds) {
  const double machine = machine_busy_seconds(), self = self_seconds(), wall = wall_seconds();
  std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
  const double machine_end = machine_busy_seconds(), elapsed = wall_seconds() - wall;
  if (machine < 0.0 || machine_end < 0.0 || elapsed <= 0.0) return -1.0;
  return std::max(0.0, ((machine_end - machine) - (self_seconds() - self)) / elapsed);
}

}  // namespace fem
