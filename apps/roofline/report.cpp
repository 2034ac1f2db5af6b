#include "apps/roofline/report.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "common/json.hpp"

namespace fem::roofline {

namespace {

std::string fixed(double v, int digits) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(digits) << v;
  return out.str();
}

// Three significant digits, as the other lessons print times.
std::string sig(double v) {
  std::ostringstream out;
  out << std::setprecision(3) << v;
  return out.str();
}

std::string size(std::size_t bytes) {
  if (bytes >= (std::size_t(1) << 20)) return sig(double(bytes) / (1 << 20)) + " MiB";
  return sig(double(bytes) / 1024) + " KiB";
}

std::string run_name(const ChapterRun& r) {
  return "`" + r.chapter + "@" + std::to_string(r.threads) + "`";
}

// The phase whose measured time is furthest above its bound.
const PhasePoint& widest_gap(const ChapterRun& r) {
  return *std::max_element(r.phases.begin(), r.phases.end(), [](const auto& a, const auto& b) {
    return a.measured_s - a.bound_s < b.measured_s - b.bound_s;
  });
}

// Six significant digits for the JSON: the plot and the tests read them back.
std::string num(double v) {
  std::ostringstream out;
  out << std::setprecision(6) << v;
  return out.str();
}

}  // namespace

std::string roofs_table(const std::vector<Roofs>& roofs) {
  std::ostringstream out;
  out << "| roof | working set per thread |";
  for (const Roofs& r : roofs) out << " " << r.threads << " thread(s) |";
  out << " Eigen's sum (the check) | STREAM triad |\n| --- | ---: |";
  for (std::size_t k = 0; k < roofs.size(); ++k) out << " ---: |";
  out << " ---: | ---: |\n";
  for (std::size_t l = 0; l < roofs.front().levels.size(); ++l) {
    out << "| " << roofs.front().levels[l].level.name << " read, GB/s | "
        << size(roofs.front().levels[l].level.working_set) << " |";
    std::string check, triad;
    for (const Roofs& r : roofs) {
      out << " " << fixed(r.levels[l].read / 1e9, 1) << " |";
      check += (check.empty() ? "" : " / ") + fixed(r.levels[l].eigen_sum / 1e9, 1);
      triad += (triad.empty() ? "" : " / ") + fixed(r.levels[l].triad / 1e9, 1);
    }
    out << " " << check << " | " << triad << " |\n";
  }
  for (const bool is_double : {true, false}) {
    out << "| peak multiply-add, " << (is_double ? "double" : "float") << ", Gflop/s | |";
    for (const Roofs& r : roofs)
      out << " " << fixed((is_double ? r.peak_double : r.peak_float) / 1e9, 1) << " |";
    out << " | |\n";
  }
  return out.str();
}

std::string roofs_check(const std::vector<Roofs>& roofs) {
  std::ostringstream out;
  out << "The memory roof against its second measurement (Eigen's sum of the same size):";
  for (const Roofs& r : roofs) {
    const LevelRoof& memory = r.levels.back();
    const double gap = std::abs(memory.eigen_sum - memory.read) / memory.read;
    out << " " << fixed(100 * gap, 0) << "% apart at " << r.threads << " thread(s)"
        << (gap <= 0.15 ? "" : " (**more than 15%: a busy machine?**)") << ";";
  }
  std::string text = out.str();
  text.back() = '.';
  return text + "\n";
}

std::string chapters_table(const std::vector<ChapterRun>& runs) {
  std::ostringstream out;
  out << "| chapter | mesh | CG it. | step, ms | the roofs allow, ms | of the bound | the phase "
         "furthest above its roof |\n| --- | --- | ---: | ---: | ---: | ---: | --- |\n";
  for (const ChapterRun& r : runs) {
    const PhasePoint& gap = widest_gap(r);
    out << "| " << run_name(r) << " | " << r.mesh << " | " << sig(r.iterations) << " | "
        << sig(1e3 * r.step_s) << " | " << sig(1e3 * r.bound_s) << " | "
        << fixed(100 * r.bound_s / r.step_s, 0) << "% | " << gap.work.phase << " ("
        << sig(1e3 * (gap.measured_s - gap.bound_s)) << " ms above) |\n";
  }
  return out.str();
}

std::string phases_table(const std::vector<ChapterRun>& runs) {
  std::ostringstream out;
  out << "| chapter | phase | MB | Mflop | flop/byte | working set (fits) | the roofs allow, ms | "
         "measured, ms | of the bound |\n| --- | --- | ---: | ---: | ---: | --- | ---: | ---: | "
         "---: |\n";
  for (const ChapterRun& r : runs)
    for (const PhasePoint& p : r.phases) {
      const double flops = p.work.flops_double + p.work.flops_float;
      out << "| " << run_name(r) << " | " << p.work.phase << " | " << sig(p.work.bytes / 1e6)
          << " | " << sig(flops / 1e6) << " | " << sig(flops / p.work.bytes) << " | "
          << size(std::size_t(p.work.working_set)) << " (" << p.level << ") | "
          << sig(1e3 * p.bound_s) << " | " << sig(1e3 * p.measured_s) << " | "
          << fixed(100 * p.bound_s / std::max(p.measured_s, 1e-12), 0) << "% |\n";
    }
  return out.str();
}

std::string json_data(const std::vector<Roofs>& roofs, const std::vector<ChapterRun>& runs) {
  std::ostringstream out;
  out << "{\"roofs\": [";
  for (std::size_t k = 0; k < roofs.size(); ++k) {
    const Roofs& r = roofs[k];
    out << (k ? ", " : "") << "{\"threads\": " << r.threads
        << ", \"peak_double\": " << num(r.peak_double) << ", \"peak_float\": " << num(r.peak_float)
        << ", \"levels\": [";
    for (std::size_t l = 0; l < r.levels.size(); ++l)
      out << (l ? ", " : "") << "{\"name\": " << json_string(r.levels[l].level.name)
          << ", \"working_set\": " << r.levels[l].level.working_set
          << ", \"read\": " << num(r.levels[l].read)
          << ", \"eigen_sum\": " << num(r.levels[l].eigen_sum)
          << ", \"triad\": " << num(r.levels[l].triad) << "}";
    out << "]}";
  }
  out << "], \"runs\": [";
  for (std::size_t k = 0; k < runs.size(); ++k) {
    const ChapterRun& r = runs[k];
    out << (k ? ", " : "") << "{\"chapter\": " << json_string(r.chapter)
        << ", \"mesh\": " << json_string(r.mesh) << ", \"threads\": " << r.threads
        << ", \"nodes\": " << r.nodes << ", \"iterations\": " << num(r.iterations)
        << ", \"step_s\": " << num(r.step_s) << ", \"bound_s\": " << num(r.bound_s)
        << ", \"phases\": [";
    for (std::size_t p = 0; p < r.phases.size(); ++p) {
      const PhasePoint& q = r.phases[p];
      out << (p ? ", " : "") << "{\"phase\": " << json_string(q.work.phase)
          << ", \"bytes\": " << num(q.work.bytes)
          << ", \"flops_double\": " << num(q.work.flops_double)
          << ", \"flops_float\": " << num(q.work.flops_float)
          << ", \"working_set\": " << num(q.work.working_set)
          << ", \"level\": " << json_string(q.level) << ", \"bound_s\": " << num(q.bound_s)
          << ", \"measured_s\": " << num(q.measured_s) << "}";
    }
    out << "]}";
  }
  return out.str() + "]}";
}

}  // namespace fem::roofline
