// Chapter 14's lesson table: `fem_lessons every-lane` (see lesson.hpp).
#include "chapters/14_every_lane/lesson.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <functional>
#include <iomanip>
#include <optional>
#include <sstream>
#include <string>

#include "chapters/09_threads/parallel.hpp"
#include "chapters/10_multigrid/v_cycle.hpp"
#include "chapters/10_multigrid/work.hpp"
#include "chapters/14_every_lane/row_pairs.hpp"
#include "chapters/14_every_lane/stepper.hpp"
#include "common/statistics.hpp"
#include "common/threads.hpp"

namespace fem::ch14 {

namespace {

constexpr int kCalls = 100;  // calls per timing, in one parallel region as the V-cycle runs them

// Microseconds per call of `call` (by every thread of the team), the median of `repeat`
// timings of kCalls calls.
double us_per_call(int threads, const std::function<void()>& call, int repeat) {
  const ThreadCountScope scope(threads);
  return 1e3 / kCalls * time_ms(repeat, [&] {
           ch09::run_parallel([&] {
             for (int k = 0; k < kCalls; ++k) call();
           });
         });
}

// The four layouts of the finest level, on this stepper's float level.
struct Layouts {
  FloatLevel& padded;  // chapter 12's, read by the V-cycle's generic kernels
  LaneFineLevel pairs;
  RowPairFineLevel row_pairs;
  PackedFineLevel packed;
  const std::vector<int>& part;
  int step;  // a smoothing step after the first, as the roofline times it
};

std::function<void()> smoothing(Layouts& l, int layout) {
  auto& v = l.padded.vectors;
  return [&l, layout, &v] {
    ch09::for_parts(l.part, true, [&](int first, int last) {
      if (layout == 0) ch10::smooth(l.padded, l.step, first, last, v.b, &v.x, v.y, true);
      if (layout == 1) smooth_rows(l.pairs, l.step, first, last, v.b, &v.x, v.y);
      if (layout == 2) smooth_rows(l.row_pairs, l.step, first, last, v.b, &v.x, v.y);
      if (layout == 3) smooth_rows(l.packed, l.step, first, last, v.b, &v.x, v.y);
    });
  };
}

std::function<void()> residual(Layouts& l, int layout) {
  auto& v = l.padded.vectors;
  return [&l, layout, &v] {
    ch09::for_parts(l.part, true, [&](int first, int last) {
      if (layout == 0) ch10::residual(l.padded, first, last, v.b, v.x);
      if (layout == 1) residual_rows(l.pairs, first, last, v.b, v.x);
      if (layout == 2) residual_rows(l.row_pairs, first, last, v.b, v.x);
      if (layout == 3) residual_rows(l.packed, first, last, v.b, v.x);
    });
  };
}

// Microseconds of one step of `stepper`.
double step_us(Stepper& stepper, State& state) {
  const auto start = std::chrono::steady_clock::now();
  stepper.step(state);
  return std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start)
      .count();
}

// Whole steps, what the layout's choice is for: chapter 12's stepper and this chapter's, the
// latter in each layout in turn (LaneVCycle::force: the same object, the same arrays, and the
// same bits in either layout), each from rest. A round: chapter 12's step, this chapter's in
// the two layouts one after the other (padded first in even rounds, packed in odd, so that a
// drift of the machine weighs on both alike), chapter 12's again; three rounds first untimed.
// The two adjacent steps of a round are a pair: in how many rounds the packed was the shorter
// says whether the medians' difference is the layouts' or the machine's (a sign test). A row
// per thread count, microseconds a step.
void step_rows(const Scene& scene, int threads_max, int rounds, std::ostream& out) {
  ch12::HalfBytesStepper old(scene, {});
  EveryLaneStepper lanes(scene, {});
  LaneVCycle& cycle = lanes.preconditioner().lane_v_cycle();
  State old_state = rest_state(scene), lanes_state = old_state;
  for (int threads = 1; threads <= threads_max; ++threads) {
    const ThreadCountScope scope(threads);
    const AskedThreadsScope asked(true);  // chapter 09's adaptive team keeps the count
    std::vector<double> old_us, padded_us, packed_us;
    int packed_shorter = 0;
    for (int round = 0; round < 3 + rounds; ++round) {
      progress(mesh_name(scene) + ": whole steps on " + std::to_string(threads) +
               " thread(s), round " + std::to_string(round + 1) + " of " +
               std::to_string(3 + rounds));
      std::array<double, 4> us{step_us(old, old_state)};
      for (const int k : {1, 2}) {
        const bool padded = (k == 1) == (round % 2 == 0);
        cycle.force(padded ? Layout::padded : Layout::packed);
        us[padded ? 1 : 2] = step_us(lanes, lanes_state);
      }
      us[3] = step_us(old, old_state);
      if (round < 3) continue;
      old_us.insert(old_us.end(), {us[0], us[3]});
      padded_us.push_back(us[1]);
      packed_us.push_back(us[2]);
      packed_shorter += us[2] < us[1];
    }
    out << "| one step (" << rounds << " rounds; packed shorter in " << packed_shorter << ") | "
        << threads << " | " << std::setprecision(0) << median(old_us) << " | " << median(padded_us)
        << " | x" << std::setprecision(2) << median(old_us) / median(padded_us) << " | "
        << std::setprecision(0) << median(packed_us) << " | x" << std::setprecision(2)
        << median(old_us) / median(packed_us) << " | | | | |\n";
  }
}

// The kernels' rows: each layout's smoothing step and residual at 1 and 2 threads.
void kernel_rows(Layouts& l, const std::string& mesh, int threads_max, int repeat,
                 std::ostream& out) {
  // Bytes per call: the lanes' own count, and chapter 12's (3x3 floats and an index a block).
  const PhaseWork lanes_step = l.pairs.smoothing_work(), lanes_residual = l.pairs.residual_work();
  const double blocks = double(l.pairs.blocks.blocks()), rows = l.pairs.blocks.rows();
  const double padded_more = 36.0 * blocks + 4.0 * (blocks + rows + 1) - l.pairs.blocks.bytes();
  out << std::fixed << "| " << mesh << " (" << int(rows) << " rows, " << int(blocks)
      << " blocks), finest level, float | threads | chapter 12, us | pair lanes, us | speedup | "
         "packed pairs, us | speedup | row pairs, us | speedup | KB per call: 12 / pair lanes | "
         "pair lanes, GB/s |\n"
      << "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n";
  const auto row = [&](const char* name, const PhaseWork& work, auto kernel) {
    for (int threads = 1; threads <= threads_max; ++threads) {
      const double old_us = us_per_call(threads, kernel(l, 0), repeat);
      const double pair_us = us_per_call(threads, kernel(l, 1), repeat);
      const double row_us = us_per_call(threads, kernel(l, 2), repeat);
      const double packed_us = us_per_call(threads, kernel(l, 3), repeat);
      out << "| " << name << " | " << threads << " | " << std::setprecision(2) << old_us << " | "
          << pair_us << " | x" << old_us / pair_us << " | " << packed_us << " | x"
          << old_us / packed_us << " | " << row_us << " | x" << old_us / row_us << " | "
          << std::setprecision(0) << 1e-3 * (work.bytes() + padded_more) << " / "
          << 1e-3 * work.bytes() << " | " << std::setprecision(1) << 1e-3 * work.bytes() / pair_us
          << " |\n";
    }
  };
  row("smoothing step", lanes_step, smoothing);
  row("residual", lanes_residual, residual);
}

// Microseconds of one fill of the stepper's own layout (the one its V-cycle runs on), 1 thread.
double fill_us(LaneVCycle& cycle, const std::vector<int>& part, int repeat) {
  return us_per_call(
      1,
      [&] {
        cycle.with_fine_level([&](auto& fine) {
          ch09::for_parts(part, true, [&](int first, int last) { fine.fill(first, last); });
        });
      },
      repeat);
}

// The layout the stepper chose on each team size it has run (LaneVCycle::measured).
std::string stepper_layouts(const LaneVCycle& cycle, int threads_max) {
  std::string said;
  for (int n = 1; n <= threads_max; ++n) {
    const std::optional<Layout> layout = cycle.measured(n);
    if (!layout) continue;
    said += std::string(said.empty() ? "" : ", ") +
            (*layout == Layout::padded ? "padded" : "packed") + " at " + std::to_string(n) +
            (n == 1 ? " thread" : " threads");
  }
  return said.empty() ? "in neither layout yet" : said;
}

std::string every_lane_table(const Scene& scene, int repeat) {
  EveryLaneStepper stepper(scene, {});
  State state = rest_state(scene);
  const int threads_max = std::min(2, max_threads());
  LaneVCycle& cycle = stepper.preconditioner().lane_v_cycle();
  // Steps on each team size in turn (at least three), until the stepper has timed its layouts
  // on each: in its first prepare on each.
  const auto chosen = [&] {
    for (int n = 1; n <= threads_max; ++n)
      if (!cycle.measured(n)) return false;
    return true;
  };
  for (int k = 0; k < 3 || (cycle.lanes() && k < 60 && !chosen()); ++k) {
    const ThreadCountScope scope(1 + k % threads_max);
    const AskedThreadsScope asked(true);  // chapter 09's adaptive team keeps the count
    stepper.step(state);
  }
  if (!cycle.lanes()) return "(" + mesh_name(scene) + ": one level, no finest level to fill)\n";
  FloatLevel& padded = stepper.preconditioner().reduced().v_cycle().fine_level();
  Layouts l{padded,
            LaneFineLevel(padded),
            RowPairFineLevel(padded),
            PackedFineLevel(padded),
            source_level(padded).rows.part,
            std::min(1, ch10::smoothing_steps(padded) - 1)};
  l.pairs.fill(0, l.pairs.blocks.rows());
  l.row_pairs.fill(0, l.row_pairs.blocks.rows());
  l.packed.fill(0, l.packed.blocks.rows());
  std::ostringstream out;
  kernel_rows(l, mesh_name(scene), threads_max, repeat, out);
  step_rows(scene, threads_max, repeat, out);
  out << "\nMedians of " << repeat << " timings. The stepper's V-cycle runs this level "
      << stepper_layouts(cycle, threads_max)
      << " (the shorter median of five fills and cycles of each, in its first step on that "
         "team); filling it from the double blocks takes "
      << std::setprecision(1) << fill_us(cycle, l.part, repeat) << " us at 1 thread.\n";
  return out.str();
}

void add_options(ArgParser& args) {
  args.option("meshes", "LIST", "further meshes, comma-separated: a table for each", "");
}

// --steps: the timings of each kernel, their median; fewer on a large mesh (at least 5), so that
// each kernel takes about as long as on a mesh of 200,000 blocks.
int timings(const Scene& scene, int steps) {
  const double blocks = 3.7 * scene.mesh.num_tets();  // the block rows hold about 3.7 a tet
  return std::clamp(int(steps * 200000.0 / blocks), std::min(5, steps), steps);
}

std::string tables(const LessonRun& run) {
  std::string out = every_lane_table(run.scene, timings(run.scene, run.steps));
  for (const Scene& scene : more_meshes(run))
    out += "\n" + every_lane_table(scene, timings(scene, run.steps));
  return out + "\nA timing: " + std::to_string(kCalls) +
         " calls in one parallel region, on the level of the 3rd step (in the L2 or L3 cache "
         "where it fits, else memory); a step's: the median of whole steps, chapter 12's and one "
         "chapter 14 stepper's in each layout (forced) in turn. " +
         measured_on() + ". Generated by `fem_lessons every-lane`.\n";
}

}  // namespace

std::vector<Lesson> lessons() {
  Lesson lesson{"every-lane",
                "the finest level's float kernels alone: chapter 12's 4 lanes, the pair lanes, "
                "the row pairs; one V-cycle with each",
                "meshes/plate_poster.msh",
                add_options,
                tables,
                true};
  // Beside the plate's level in cache, one larger than this machine's last cache
  // (./tutorial.sh meshes --large makes it).
  lesson.record_meshes_if_present = {"meshes/generated/beam_50k.msh"};
  return {lesson};
}

}  // namespace fem::ch14
