#include "apps/roofline/placement.hpp"

#include <algorithm>
#include <memory>
#include <stdexcept>

#include "chapters/course.hpp"
#include "common/lesson.hpp"
#include "common/threads.hpp"

namespace fem::roofline {

namespace {

// A StepProfile phase by its name in the results ("forces", ..., "step").
const PhaseCost& phase_cost(const StepProfile& p, const std::string& phase) {
  for (const StepProfile::Phase& entry : StepProfile::phases())
    if (phase == entry.name) return p.*entry.cost;
  throw std::logic_error("no phase '" + phase + "' in StepProfile");
}

// The counters over `steps` steps, per step.
ExecutedWork per_step(ExecutedWork e, int steps) {
  const double n = std::max(steps, 1);
  e.steps /= n;
  e.rotations /= n;
  e.rotation_iterations /= n;
  e.rotation_fallbacks /= n;
  return e;  // the team is the last step's
}

// What one phase of the measured steps did: its median time, and its synchronizations and
// their waiting per step (means: each step's count priced at the team that step ran on).
struct PhaseRecord {
  double seconds = 0.0, regions = 0.0, barriers = 0.0, waiting_s = 0.0;
};
PhaseRecord record_phase(const std::string& phase, const std::vector<StepProfile>& profiles,
                         const std::vector<int>& teams, const Roofs& roofs) {
  PhaseRecord out;
  std::vector<double> seconds;
  for (std::size_t k = 0; k < profiles.size(); ++k) {
    const PhaseCost& cost = phase_cost(profiles[k], phase);
    seconds.push_back(cost.seconds);
    out.regions += double(cost.regions);
    out.barriers += double(cost.barriers);
    out.waiting_s += waiting_seconds(roofs, teams[k], double(cost.regions), double(cost.barriers));
  }
  const double n = double(std::max<std::size_t>(profiles.size(), 1));
  out.seconds = median(seconds);
  out.regions /= n;
  out.barriers /= n;
  out.waiting_s /= n;
  return out;
}

PhasePoint place_phase(const PhaseWork& w, const PhaseRecord& record, const Roofs& roofs) {
  PhasePoint point;
  point.work = w;
  point.level = fitting_levels(roofs, w);
  point.memory_s = memory_seconds(roofs, w);
  point.arithmetic_s = arithmetic_seconds(roofs, w);
  point.regions = record.regions;
  point.barriers = record.barriers;
  point.waiting_s = record.waiting_s;
  point.bound_s = bound_seconds(roofs, w) + point.waiting_s;
  point.measured_s = record.seconds;
  return point;
}

// The stepper at the roofs' thread count: `warmup` steps, then `steps` measured.
PlacedRun measure(const ChapterInfo& chapter, Stepper& stepper, const Scene& scene,
                  const Roofs& roofs, int warmup, int steps) {
  const ThreadCountScope team(roofs.threads);
  PlacedRun run;
  run.mesh = mesh_name(scene);
  run.chapter = chapter.id;
  run.nodes = scene.mesh.num_nodes();
  run.tets = scene.mesh.num_tets();
  run.threads = roofs.threads;
  State state = rest_state(scene);
  std::vector<StepProfile> profiles;
  std::vector<int> teams;  // the threads each measured step ran on (0: not said)
  const ChapterWork& work = course_of(chapter).work;
  const auto executed = [&] { return work.executed ? work.executed(stepper) : ExecutedWork{}; };
  ExecutedWork before;
  for (int k = 0; k < warmup + steps; ++k) {
    if (k == warmup) before = executed();
    stepper.step(state);
    if (k < warmup) continue;
    profiles.push_back(stepper.profile());
    teams.push_back(static_cast<int>(executed().team));
    run.team_min = k == warmup ? teams.back() : std::min(run.team_min, teams.back());
    run.team_max = std::max(run.team_max, teams.back());
  }
  run.executed = per_step(executed().since(before), steps);
  const PhaseRecord step = record_phase("step", profiles, teams, roofs);
  run.step_s = step.seconds;
  run.regions = step.regions;
  run.barriers = step.barriers;
  run.waiting_s = step.waiting_s;
  std::vector<double> iterations;
  for (const StepProfile& p : profiles) iterations.push_back(p.cg_iterations);
  run.iterations = median(iterations);
  if (!work.count) return run;  // measured, not counted
  for (const PhaseWork& w : work.count(stepper, scene, WorkCounts{run.iterations, run.executed})) {
    run.phases.push_back(place_phase(w, record_phase(w.phase, profiles, teams, roofs), roofs));
    run.bound_s += run.phases.back().bound_s;
  }
  return run;
}

}  // namespace

std::vector<PlacedRun> place_chapter(const ChapterInfo& chapter, const Scene& scene,
                                     const std::vector<Roofs>& roofs, int warmup, int steps) {
  progress("roofline: " + chapter.id + " on " + mesh_name(scene));
  std::unique_ptr<Stepper> stepper = chapter.make(scene, SolverSettings{});
  const bool threaded = stepper->uses_threads();
  std::vector<PlacedRun> runs;
  for (const Roofs& r : roofs) {
    if (r.threads > 1 && !threaded) continue;
    // A fresh stepper per thread count, as fem_bench makes one per run: the steps from rest
    // then see the same guesses, predictions and adaptive team as the bench's.
    if (!stepper) stepper = chapter.make(scene, SolverSettings{});
    runs.push_back(measure(chapter, *stepper, scene, r, warmup, steps));
    stepper.reset();
  }
  return runs;
}

}  // namespace fem::roofline
