#include "apps/roofline/bandwidth.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <vector>

#include "apps/roofline/best_rate.hpp"

namespace fem::roofline {

namespace {

using Packet = Eigen::internal::packet_traits<double>::type;
constexpr int kLanes = Eigen::internal::packet_traits<double>::size;
// Packets per stride of the read, write and update loops: four, as likwid-bench's load_*,
// store_* and update_* kernels (their "Inner loop executions": 16000 for 512000 doubles with
// AVX-512). Fewer branches do not make a faster loop: on the Zen 5 VM a stride of sixteen
// 64-byte packets read a 4 MiB array (in L3) at 100-108 GB/s in every run where four
// packets, likwid-bench's stride, read it at 119-130 and likwid-bench at 119-124 (a scratch
// copy of this loop, runs of 0.5 s, alternated); in L1 and L2 the two strides ran alike.
constexpr int kPackets = 4;
constexpr std::size_t kStride = kPackets * kLanes;

// Elements per thread for `bytes`, whole strides of the read kernel, at least one.
std::size_t elements(std::size_t bytes) {
  return std::max<std::size_t>(1, bytes / sizeof(double) / kStride) * kStride;
}

// Passes over the array per call of the read kernel: at least kCallBytes read, so that the
// set-up and the final sum of a call (a hundred cycles or so) stay small beside an array in
// L1, which one pass reads in a few hundred cycles.
constexpr std::size_t kCallBytes = std::size_t(1) << 20;
int passes(std::size_t n) {
  return int(std::max<std::size_t>(1, kCallBytes / (n * sizeof(double))));
}

// Keeps a loaded packet without an instruction: an empty asm statement that takes it in a
// vector register ("v" on x86: any xmm/ymm/zmm, "w" on AArch64), so the compiler must load it
// and need not compute anything from it. Any arithmetic on the loads costs the loop issue slots
// beside its loads, which an array in L1 delivers two a cycle: Eigen's sum(), an addition per
// load, runs well under the read roof there (the roofline's own table), and even one bitwise
// operation per two loads stayed 15-18% under likwid-bench's load kernel on an AVX-512 Xeon.
inline void keep(const Packet& packet) {
#if defined(__x86_64__) || defined(__i386__)
  asm volatile("" ::"v"(packet));
#elif defined(__aarch64__)
  asm volatile("" ::"w"(packet));
#else
  asm volatile("" ::"g"(packet));
#endif
}

// The read kernel, `passes` passes over the array: Eigen's packet loads (pload,
// Eigen/src/Core/GenericPacketMath.h and the target's PacketMath.h) and nothing else, as
// likwid-bench's load_* kernels, the loop's own increment and branch aside.
double read_passes(const Eigen::VectorXd& a, int passes) {
  using namespace Eigen::internal;
  const double* data = a.data();
  const Eigen::Index n = a.size();
  for (int pass = 0; pass < passes; ++pass)
    for (Eigen::Index i = 0; i < n; i += kStride)
      for (int k = 0; k < kPackets; ++k) keep(pload<Packet>(data + i + k * kLanes));
  return data[0];
}

// One pass of the write kernel: a packet store per packet of the array, kPackets packets per
// stride as the read's (pstore, Eigen/src/Core/GenericPacketMath.h), of a value that changes
// per pass so that no pass is dropped.
double write_pass(Eigen::VectorXd& a) {
  using namespace Eigen::internal;
  const Packet value = pset1<Packet>(a[0] + 1.0);
  double* data = a.data();
  for (Eigen::Index i = 0; i < a.size(); i += kStride)
    for (int k = 0; k < kPackets; ++k) pstore(data + i + k * kLanes, value);
  return a[0];
}

// One pass of the update kernel: each packet loaded and stored back where it was, as
// likwid-bench's update_* kernels do; the empty asm statement takes the packet as changed, so
// that the compiler must store it (a store of what was just loaded would be dropped).
double update_pass(Eigen::VectorXd& a) {
  using namespace Eigen::internal;
  double* data = a.data();
  for (Eigen::Index i = 0; i < a.size(); i += kStride)
    for (int k = 0; k < kPackets; ++k) {
      Packet packet = pload<Packet>(data + i + k * kLanes);
#if defined(__x86_64__) || defined(__i386__)
      asm volatile("" : "+v"(packet));
#elif defined(__aarch64__)
      asm volatile("" : "+w"(packet));
#else
      asm volatile("" : "+g"(packet));
#endif
      pstore(data + i + k * kLanes, packet);
    }
  return data[0];
}

}  // namespace

std::vector<CacheLevel> cache_levels() {
  std::vector<CacheLevel> levels;
  for (const CacheLevel& c : machine_record().caches)
    if (c.type != "Instruction" && c.level > 0 && c.bytes > 0) levels.push_back(c);
  std::sort(levels.begin(), levels.end(),
            [](const CacheLevel& a, const CacheLevel& b) { return a.level < b.level; });
  return levels.empty() ? fallback_levels() : levels;
}

std::vector<CacheLevel> fallback_levels() {
  return {{1, "Data", 32LL << 10, 1}, {2, "Unified", 1LL << 20, 1}, {3, "Unified", 32LL << 20, 64}};
}

std::vector<MemoryLevel> memory_levels(const std::vector<CacheLevel>& caches, int threads) {
  std::vector<MemoryLevel> levels;
  std::size_t largest = 0, inner = 0;
  for (const CacheLevel& c : caches) {
    // A shared cache holds every thread's data: each thread gets its share.
    const int sharing = std::min(std::max(threads, 1), c.shared_by);
    const std::size_t per_thread = std::size_t(c.bytes) / static_cast<std::size_t>(sharing);
    // Half the level (a working set is placed in a level only up to the size its roof was
    // measured on: fitting_level), but no more than eight times the level inside it (a private
    // cache: the array is then out of the inner level and well inside this one; on the Zen 5
    // VM, at exactly half its 1 MiB L2 our read and likwid-bench's ran 15-30% faster than at
    // 384 KiB, and apart from each other from run to run), four times for a shared level (also
    // where a virtual machine reports a last-level cache far larger than the share its host
    // gives it). A core's private caches are its own, their sizes true also in a VM.
    const std::size_t times_inner = c.shared_by > 1 ? 4 : 8;
    const std::size_t working_set =
        inner > 0 ? std::min(per_thread / 2, times_inner * inner) : per_thread / 2;
    levels.push_back({"L" + std::to_string(c.level), per_thread, working_set, c.shared_by > 1});
    largest = std::max(largest, std::size_t(c.bytes));
    inner = per_thread;
  }
  const std::size_t memory = std::max<std::size_t>(largest, std::size_t(8) << 20) * 4;
  levels.push_back({"memory", 0, memory / static_cast<std::size_t>(std::max(threads, 1))});
  return levels;
}

double read_bandwidth(std::size_t bytes, int threads, double seconds, int timings) {
  const std::size_t n = elements(bytes);
  const int p = passes(n);
  return best_rate(
      threads, seconds, double(p * n * sizeof(double)),
      [n] { return Eigen::VectorXd::Constant(Eigen::Index(n), 1.0).eval(); },
      [p](const Eigen::VectorXd& a) { return read_passes(a, p); }, timings);
}

int read_packets() { return kPackets; }

double write_bandwidth(std::size_t bytes, int threads, double seconds, int timings) {
  const std::size_t n = elements(bytes);
  return best_rate(
      threads, seconds, double(n * sizeof(double)),
      [n] { return Eigen::VectorXd::Constant(Eigen::Index(n), 1.0).eval(); },
      [](Eigen::VectorXd& a) { return write_pass(a); }, timings);
}

double update_bandwidth(std::size_t bytes, int threads, double seconds, int timings) {
  const std::size_t n = elements(bytes);
  return best_rate(
      threads, seconds, 2.0 * double(n * sizeof(double)),
      [n] { return Eigen::VectorXd::Constant(Eigen::Index(n), 1.0).eval(); },
      [](Eigen::VectorXd& a) { return update_pass(a); }, timings);
}

double zero_bandwidth(std::size_t bytes, int threads, double seconds) {
  using Blocks = std::vector<Eigen::Matrix3d>;
  const std::size_t n = std::max<std::size_t>(1, bytes / sizeof(Eigen::Matrix3d));
  return best_rate(
      threads, seconds, double(n * sizeof(Eigen::Matrix3d)),
      [n] { return Blocks(n, Eigen::Matrix3d::Ones()); },
      [](Blocks& blocks) {
        for (Eigen::Matrix3d& block : blocks) block.setZero();  // compose's loop
        return blocks[0](0, 0);
      });
}

double eigen_sum_bandwidth(std::size_t bytes, int threads, double seconds, int timings) {
  const std::size_t n = elements(bytes);
  return best_rate(
      threads, seconds, double(n * sizeof(double)),
      [n] { return Eigen::VectorXd::Constant(Eigen::Index(n), 1.0).eval(); },
      [](const Eigen::VectorXd& a) { return a.sum(); }, timings);
}

double triad_bandwidth(std::size_t bytes, int threads, double seconds) {
  struct Arrays {
    Eigen::VectorXd a, b, c;
  };
  const Eigen::Index n = Eigen::Index(elements(bytes));
  return best_rate(
      threads, seconds, 3.0 * double(n) * sizeof(double),
      [n] {
        return Arrays{Eigen::VectorXd::Zero(n), Eigen::VectorXd::Constant(n, 1.0),
                      Eigen::VectorXd::Constant(n, 2.0)};
      },
      [](Arrays& s) {
        s.a.noalias() = s.b + 0.5 * s.c;
        return s.a[0];
      });
}

}  // namespace fem::roofline
