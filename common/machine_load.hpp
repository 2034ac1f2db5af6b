// How busy the machine is while a program measures. Times measured while other programs run
// are not the code's: threads that wait for each other at barriers suffer most (one thread
// paused by the operating system stalls the others), and a shared virtual machine also loses
// time to its neighbours (the "steal" time of /proc/stat). Every measuring program records
// this beside its numbers and warns when the machine was busy (fem_bench, fem_multigrid).
#pragma once

#include <string>

#include "common/json.hpp"

namespace fem {

// The 1-minute load average (/proc/loadavg), -1 where unknown. It lags: a build that ended a
// minute ago still weighs in it.
double load_average();

// Watches an interval of work: the 1-minute load average at its start and end, and the CPU
// time that other processes (and the hypervisor) took from the machine meanwhile: the
// machine's busy time (/proc/stat: user, nice, system, irq, softirq, steal) minus this
// process's own (getrusage), over the wall time, as a number of cores. Linux only; elsewhere
// other_cpus() is -1 and busy() false.
class LoadMonitor {
 public:
  LoadMonitor();  // the interval starts
  void stop();    // the interval ends (the first call counts; later ones do nothing)
  double load_before() const { return load_before_; }
  double load_after() const { return load_after_; }
  // Cores used on average by other processes during the interval; -1 where unknown.
  double other_cpus() const { return other_cpus_; }
  unsigned cores() const { return cores_; }
  // Other processes used more than kBusyCores cores, or a tenth of the machine if that is more.
  bool busy() const;
  // One line for the user when busy(), else "".
  std::string warning() const;
  // Adds the fields "load_average": [before, after], "other_cpus" (null where unknown) and
  // "busy" to a JSON object (bench.json's "machine").
  void add_json_fields(Json& machine) const;

  static constexpr double kBusyCores = 0.25;

 private:
  double load_before_ = -1.0, load_after_ = -1.0, other_cpus_ = -1.0;
  double machine_start_ = -1.0, self_start_ = 0.0, wall_start_ = 0.0;
  unsigned cores_ = 1;
  bool stopped_ = false;
};

// A quick look before the work: the cores other processes use over the next `seconds` (this
// process sleeps meanwhile), -1 where unknown. For a note such as "the machine is busy now".
double other_cpus_now(double seconds = 0.3);

}  // namespace fem
