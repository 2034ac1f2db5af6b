// The kernels alone as the roofline lesson prints and records them (kernels_alone.hpp).
#include <algorithm>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <sstream>

#include "apps/roofline/kernels_alone.hpp"
#include "common/lesson.hpp"

namespace fem::roofline {

namespace {

std::string ms(double seconds) {
  std::ostringstream out;
  out << std::setprecision(3) << 1e3 * seconds;
  return out.str();
}

std::string us(double seconds) {
  std::ostringstream out;
  out << std::setprecision(3) << 1e6 * seconds;
  return out.str();
}

std::string name(const AloneRun& r) {
  return "`" + r.chapter + "@" + std::to_string(r.threads) + "`";
}

// The solve's time beyond its bound, in two: the kernels alone beyond their parts' bound (in
// the core), and the solve beyond its kernels alone and the rest's bound (between them).
double in_core(const AloneRun& r) { return r.alone_s - r.parts_bound_s; }
double between(const AloneRun& r) {
  return r.solve_s - r.alone_s - std::max(r.solve_bound_s - r.parts_bound_s, 0.0);
}

}  // namespace

std::string kernels_alone_table(const std::vector<AloneRun>& runs) {
  if (runs.empty()) return "";
  std::ostringstream out;
  out << "\n| chapter | kernel alone | calls per step | us per call | the roofs allow, us | of "
         "the bound | ms per step |\n| --- | --- | ---: | ---: | ---: | ---: | ---: |\n";
  for (const AloneRun& r : runs)
    for (const KernelAlone& k : r.kernels)
      out << "| " << name(r) << " | " << k.name << " | " << fixed(k.calls, 0) << " | "
          << us(k.seconds) << " | " << us(k.bound_s) << " | "
          << fixed(100 * k.bound_s / std::max(k.seconds, 1e-12), 0)
          << (k.bound_s > k.seconds ? "% (faster than its bound) | " : "% | ")
          << ms(k.calls * k.seconds) << " |\n";
  out << "\n| chapter | solve, ms | its bound | the kernels alone (their parts' bound) | in the "
         "core | between the kernels | the solve's waiting |\n| --- | ---: | ---: | ---: | ---: "
         "| ---: | ---: |\n";
  for (const AloneRun& r : runs)
    out << "| " << name(r) << " | " << ms(r.solve_s) << " | " << ms(r.solve_bound_s) << " | "
        << ms(r.alone_s) << " (" << ms(r.parts_bound_s) << ") | " << ms(in_core(r)) << " | "
        << ms(between(r)) << " | " << ms(r.waiting_s) << " |\n";
  out << "\nKernels alone: each of the solve's dominant kernels called again and again on the "
         "same data, the best of repeated timings, each call ending at its loop's barrier as in "
         "the solve; the solve: the best of as many steps taken in turn with those timings, the "
         "kernels' calls counted at its iterations. In the core: the kernels alone beyond their "
         "own bound (instructions, indexing, the latency of small blocks). Between the kernels: "
         "the solve beyond its kernels alone and the bound of what no kernel here stands for "
         "(short loops, data evicted between kernels, waiting).\n";
  return out.str();
}

std::string with_kernels_alone(const std::string& data, const std::vector<AloneRun>& runs) {
  nlohmann::json out = nlohmann::json::parse(data);
  nlohmann::json section = nlohmann::json::array();
  for (const AloneRun& r : runs) {
    nlohmann::json kernels = nlohmann::json::array();
    for (const KernelAlone& k : r.kernels)
      kernels.push_back({{"kernel", k.name},
                         {"part", k.part},
                         {"calls", k.calls},
                         {"seconds", k.seconds},
                         {"bound_s", k.bound_s},
                         {"bytes_read", k.work.bytes_read},
                         {"bytes_written", k.work.bytes_written},
                         {"bytes_allocated", k.work.bytes_allocated},
                         {"bytes_zeroed", k.work.bytes_zeroed},
                         {"flops", k.work.flops_double + k.work.flops_float},
                         {"working_set", k.work.working_set}});
    section.push_back({{"chapter", r.chapter},
                       {"mesh", r.mesh},
                       {"threads", r.threads},
                       {"solve_s", r.solve_s},
                       {"solve_iterations", r.solve_iterations},
                       {"solve_rounds", r.solve_rounds},
                       {"solve_bound_s", r.solve_bound_s},
                       {"parts_bound_s", r.parts_bound_s},
                       {"alone_s", r.alone_s},
                       {"in_core_s", in_core(r)},
                       {"between_s", between(r)},
                       {"waiting_s", r.waiting_s},
                       {"kernels", kernels}});
  }
  out["kernels_alone"] = section;
  return out.dump();
}

}  // namespace fem::roofline
