#include "apps/roofline/placement.hpp"

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

// The counts of a student's variant are its original's (the data it copied): a fresh original
// stepped once on the same scene, with the variant's iterations.
std::vector<PhaseWork> counted_work(const ChapterInfo& chapter, const Stepper& stepper,
                                    const Scene& scene, int iterations, std::string& counted_as) {
  try {
    return count_work(stepper, scene, iterations, counted_as);
  } catch (const std::invalid_argument&) {
    if (chapter.variant_of.empty()) throw;
  }
  const auto original = find_chapter(chapter.variant_of).make(scene, SolverSettings{});
  State state = rest_state(scene);
  original->step(state);
  return count_work(*original, scene, iterations, counted_as);
}

// The stepper at the roofs' thread count: `warmup` steps, then `steps` measured.
ChapterRun measure(const ChapterInfo& chapter, Stepper& stepper, const Scene& scene,
                   const Roofs& roofs, int warmup, int steps) {
  const ThreadCountScope team(roofs.threads);
  ChapterRun run;
  run.mesh = mesh_name(scene);
  run.chapter = chapter.id;
  run.nodes = scene.mesh.num_nodes();
  run.tets = scene.mesh.num_tets();
  run.threads = roofs.threads;
  State state = rest_state(scene);
  std::vector<StepProfile> profiles;
  for (int k = 0; k < warmup + steps; ++k) {
    stepper.step(state);
    if (k >= warmup) profiles.push_back(stepper.profile());
  }
  std::vector<double> iterations, step;
  for (const StepProfile& p : profiles) {
    iterations.push_back(p.cg_iterations);
    step.push_back(p.step.seconds);
  }
  run.iterations = median(iterations);
  run.step_s = median(step);
  const std::vector<PhaseWork> work =
      counted_work(chapter, stepper, scene, static_cast<int>(run.iterations), run.counted_as);
  for (const PhaseWork& w : work) {
    std::vector<double> seconds;
    for (const StepProfile& p : profiles) seconds.push_back(phase_seconds(p, w.phase));
    const PhasePoint point{w, fitting_level(roofs, w.working_set).level.name,
                           bound_seconds(roofs, w), median(seconds)};
    run.bound_s += point.bound_s;
    run.phases.push_back(point);
  }
  return run;
}

}  // namespace

std::vector<ChapterRun> place_chapter(const ChapterInfo& chapter, const Scene& scene,
                                      const std::vector<Roofs>& roofs, int warmup, int steps) {
  progress("roofline: " + chapter.id + " on " + mesh_name(scene));
  const auto stepper = chapter.make(scene, SolverSettings{});
  std::vector<ChapterRun> runs;
  for (const Roofs& r : roofs)
    if (r.threads == 1 || stepper->uses_threads())
      runs.push_back(measure(chapter, *stepper, scene, r, warmup, steps));
  return runs;
}

}  // namespace fem::roofline
