#include "apps/roofline/likwid.hpp"

#include <Eigen/Core>
#include <array>
#include <chrono>
#include <cstdio>
#include <memory>
#include <sstream>

namespace fem::roofline {

namespace {

// The kernel's name for the build's vector width: AVX-512 where Eigen's packets hold 8
// doubles, AVX (with FMA for the peak) where they hold 4.
std::string kernel_name(LikwidKernel kernel) {
  const bool wide = Eigen::internal::packet_traits<double>::size >= 8;
  const std::string isa = wide ? "avx512" : "avx";
  switch (kernel) {
    case LikwidKernel::load:
      return "load_" + isa;
    case LikwidKernel::store:
      return "store_" + isa;
    case LikwidKernel::update:
      return "update_" + isa;
    case LikwidKernel::peak:
      return "peakflops_" + isa + "_fma";
  }
  return "";
}

// The command's standard output and error, and its exit status.
std::string run(const std::string& command, int& status) {
  std::string out;
  const std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(command.c_str(), "r"), pclose);
  if (!pipe) {
    status = -1;
    return out;
  }
  std::array<char, 4096> buffer{};
  for (std::size_t n; (n = fread(buffer.data(), 1, buffer.size(), pipe.get())) > 0;)
    out.append(buffer.data(), n);
  status = 0;
  return out;
}

// The sum of the numbers after "<label>:" at a line's start in the processes' reports, or 0.
double field(const std::string& report, const std::string& label) {
  double sum = 0.0;
  for (std::size_t at = report.find(label + ":"); at != std::string::npos;
       at = report.find(label + ":", at + 1)) {
    if (at > 0 && report[at - 1] != '\n') continue;
    std::istringstream in(report.substr(at + label.size() + 1));
    double value = 0.0;
    in >> value;
    sum += value;
  }
  return sum;
}

}  // namespace

std::string likwid_command(LikwidKernel kernel, std::size_t bytes_per_thread, int threads,
                           double run_seconds, double expected) {
  const bool flops = kernel == LikwidKernel::peak;
  // One iteration passes once over a thread's chunk: 8 bytes an element (16 for update, which
  // counts its load and its store), and peakflops_*'s 30 flops an element (likwid-bench -l
  // peakflops_avx512_fma).
  const double per_element = flops ? 30.0 / 8.0 : kernel == LikwidKernel::update ? 2.0 : 1.0;
  const int n = std::max(threads, 1);
  const double per_iteration = double(bytes_per_thread) * per_element;
  const double run_s = std::max(run_seconds, kLikwidRunSeconds);
  const long long iterations =
      std::max(10LL, static_cast<long long>(expected / n * run_s / per_iteration));
  const std::size_t kb = std::max<std::size_t>(1, bytes_per_thread / 1024);
  // One process of one thread per CPU, started at once, each on its own array, as our roofs'
  // threads: likwid-bench's own threads (-W S0:...:2) reported less than the sum of two
  // processes (store_avx512 in L1, runs of 1.1-1.3 s: 354-440 GB/s, against 255 + 259 for two
  // processes at once, on the 2-core Zen 5 VM). taskset places each, likwid-bench's node domain
  // N being the CPUs it may use; each prints only its rate's line, so that the reports of
  // processes running at once cannot interleave.
  const std::vector<int> cpus = allowed_cpus();
  std::ostringstream command;
  command << "(";
  for (int k = 0; k < n; ++k) {
    const int cpu = k < int(cpus.size()) ? cpus[k] : k;
    command << "taskset -c " << cpu << " likwid-bench -t " << kernel_name(kernel) << " -W N:" << kb
            << "kB:1 -i " << iterations << " 2>&1 | grep -E '^(MByte|MFlops)/s:|rror' & ";
  }
  command << "wait) 2>&1";
  return command.str();
}

LikwidRate likwid_bench(LikwidKernel kernel, std::size_t bytes_per_thread, int threads,
                        double run_seconds, double expected, int runs) {
  LikwidRate r;
  r.kernel = kernel_name(kernel);
  int status = 0;
  if (run("command -v likwid-bench >/dev/null 2>&1 && echo yes", status).find("yes") ==
      std::string::npos) {
    r.note =
        "likwid-bench not installed (Debian and Ubuntu on x86-64: likwid; no package for arm64 "
        "nor macOS)";
    return r;
  }
  const bool flops = kernel == LikwidKernel::peak;
  const std::string command =
      likwid_command(kernel, bytes_per_thread, threads, run_seconds, expected);
  std::string report;
  for (int i = 0; i < runs; ++i) {
    report = run(command, status);
    r.rate = std::max(r.rate, field(report, flops ? "MFlops/s" : "MByte/s") * 1e6);
  }
  if (r.rate <= 0.0) {
    const std::size_t line = report.find('\n');
    r.note = "likwid-bench did not report: " + report.substr(0, std::min<std::size_t>(line, 120));
  }
  return r;
}

double measured_clock() {
  using Clock = std::chrono::steady_clock;
  constexpr long long kAdds = 200'000'000;
  double best = 0.0;
  for (int repeat = 0; repeat < 5; ++repeat) {
    long long x = repeat;
    const Clock::time_point start = Clock::now();
    for (long long i = 0; i < kAdds; ++i) {
      x += 1;  // each add waits for the last: one per cycle, whatever the core's width
      asm volatile("" : "+r"(x));  // kept in a register, never folded
    }
    const double t = std::chrono::duration<double>(Clock::now() - start).count();
    best = std::max(best, double(kAdds + x - x) / t);
  }
  return best;
}

}  // namespace fem::roofline
