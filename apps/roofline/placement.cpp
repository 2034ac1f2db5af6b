#include "apps/roofline/placement.hpp"

#include <algorithm>
#include <memory>
#include <stdexcept>

#include "common/lesson.hpp"
#include "common/threads.hpp"

namespace fem::roofline {

namespace {

// The measured seconds of each StepProfile phase the work counts name.
double phase_seconds(const StepProfile& p, const std::string& phase) {
  if (phase == "forces") return p.forces.seconds;
  if (phase == "dfdx") return p.dfdx.seconds;
  if (phase == "compose") return p.compose.seconds;
  if (phase == "constraints") return p.constraints.seconds;
  if (phase == "solve") return p.solve.seconds;
  throw std::logic_error("no phase '" + phase + "' in StepProfile");
}

// The counters over `steps` steps, per step.
ExecutedWork per_step(ExecutedWork e, int steps) {
  const double n = std::max(steps, 1);
  e.steps /= n;
  e.rotations /= n;
  e.rotation_iterations /= n;
  e.rotation_fallbacks /= n;
  e.regions /= n;
  e.barriers /= n;
  return e;  // the team is the last step's
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
  const auto executed = [&] {
    return chapter.work.executed ? chapter.work.executed(stepper) : ExecutedWork{};
  };
  ExecutedWork before;
  for (int k = 0; k < warmup + steps; ++k) {
    if (k == warmup) before = executed();
    stepper.step(state);
    if (k < warmup) continue;
    profiles.push_back(stepper.profile());
    const int team = static_cast<int>(executed().team);
    run.team_min = k == warmup ? team : std::min(run.team_min, team);
    run.team_max = std::max(run.team_max, team);
  }
  run.executed = per_step(executed().since(before), steps);
  run.waiting_s = run.executed.regions * roofs.region_s + run.executed.barriers * roofs.barrier_s;
  std::vector<double> iterations, step;
  for (const StepProfile& p : profiles) {
    iterations.push_back(p.cg_iterations);
    step.push_back(p.step.seconds);
  }
  run.iterations = median(iterations);
  run.step_s = median(step);
  if (!chapter.work.count) return run;  // measured, not counted
  const std::vector<PhaseWork> work =
      chapter.work.count(stepper, scene, WorkCounts{run.iterations, run.executed});
  for (const PhaseWork& w : work) {
    std::vector<double> seconds;
    for (const StepProfile& p : profiles) seconds.push_back(phase_seconds(p, w.phase));
    const PhasePoint point{w,
                           fitting_levels(roofs, w),
                           bound_seconds(roofs, w),
                           memory_seconds(roofs, w),
                           arithmetic_seconds(roofs, w),
                           median(seconds)};
    run.bound_s += point.bound_s;
    run.phases.push_back(point);
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
