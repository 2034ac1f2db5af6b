// Chapter 13's lesson table: `fem_lessons iterations` (see lesson.hpp).
#include "chapters/13_fewer_waits/lesson.hpp"

#include <functional>
#include <sstream>
#include <stdexcept>
#include <string>

#include "chapters/12_half_the_bytes/work.hpp"
#include "chapters/13_fewer_waits/stepper.hpp"
#include "chapters/13_fewer_waits/work.hpp"

namespace fem::ch13 {

namespace {

// The solve's bytes as the roofline counts them at `iterations` PCG iterations per step.
double solve_bytes(const FewerWaitsStepper& stepper, const Scene& scene, double iterations) {
  WorkCounts counts;
  counts.cg_iterations = iterations;
  for (const PhaseWork& phase : ch08::count_work(stepper, scene, counts))
    if (phase.phase == "solve") return phase.bytes();
  throw std::logic_error("the stepper's work has no solve phase");
}

// The table's rows: a name and what it changes in the chapter's settings (the first: nothing).
struct Setting {
  const char* name;
  std::function<void(ch10::MultigridSettings&)> change;
};

std::vector<Setting> settings() {
  using ch10::MultigridSettings;
  const auto degree = [](int d) {
    return [d](MultigridSettings& s) { s.relax.chebyshev_degree = d; };
  };
  const auto ratio = [](double r) {
    return [r](MultigridSettings& s) { s.relax.chebyshev_ratio = r; };
  };
  const auto jacobi = [](int sweeps) {
    return [sweeps](MultigridSettings& s) {
      s.relax.smoother = ch10::Smoother::Jacobi;
      s.relax.sweeps = sweeps;
    };
  };
  const auto coarsest = [](int dofs) {
    return [dofs](MultigridSettings& s) { s.max_coarse_dofs = dofs; };
  };
  const auto unsmoothed = [](MultigridSettings& s) { s.coarsening.smooth_prolongator = false; };
  return {{"chapter 13 (degree 3, [lambda/30, lambda], smoothed P, coarsest <= 200)",
           [](MultigridSettings&) {}},
          {"degree 2", degree(2)},
          {"degree 4", degree(4)},
          {"[lambda/60, lambda]", ratio(60.0)},
          {"degree 2, [lambda/10, lambda]",
           [](MultigridSettings& s) {
             s.relax.chebyshev_degree = 2;
             s.relax.chebyshev_ratio = 10.0;
           }},
          {"damped Jacobi, 3 sweeps", jacobi(3)},
          {"coarsest <= 1000 (2 levels)", coarsest(1000)},
          {"3 modes (translations)", [](MultigridSettings& s) { s.coarsening.modes = 3; }},
          {"unsmoothed P = T", unsmoothed},
          {"unsmoothed P = T, [lambda/60, lambda]", [unsmoothed](MultigridSettings& s) {
             unsmoothed(s);
             s.relax.chebyshev_ratio = 60.0;
           }}};
}

std::string one_mesh_table(const LessonRun& run) {
  const Scene& scene = run.scene;
  const SolverSettings solver = solver_from_args(run.args);
  const int warmup = run.args.get_int("warmup");
  std::ostringstream t;
  t << "| " << mesh_name(scene)
    << ", chapter 13 with | CG it. per step | solve MB per iteration "
       "| solve MB per step |\n"
    << "| --- | ---: | ---: | ---: |\n";
  double reference = 0.0;
  for (const Setting& setting : settings()) {
    progress(std::string(mesh_name(scene)) + ": " + setting.name);
    ch10::MultigridStepperSettings s;
    setting.change(s.multigrid);
    const IterationCost c = iteration_cost(scene, solver, s, warmup, run.steps);
    if (reference == 0.0) reference = c.bytes_per_step;
    t << "| " << setting.name << " | " << fixed(c.mean_iterations, 2) << " | "
      << fixed(c.bytes_per_iteration / 1e6, 2) << " | " << fixed(c.bytes_per_step / 1e6, 1) << " (x"
      << fixed(c.bytes_per_step / reference, 2) << ") |\n";
  }
  t << "\n"
    << scene.name << ", mean of " << run.steps << " steps after " << warmup
    << "; the roofline's solve bytes (the parts' `count_work`; refreshes not counted). "
       "`fem_lessons iterations --steps "
    << run.steps << "`.\n";
  return t.str();
}

std::string iterations_table(const LessonRun& run) { return on_every_mesh(run, one_mesh_table); }

void add_options(ArgParser& args) {
  add_solver_options(args);
  args.option("warmup", "N", "unmeasured steps first", "10");
  args.option("meshes", "LIST", "further meshes, comma-separated: a table for each", "");
}

}  // namespace

IterationCost iteration_cost(const Scene& scene, const SolverSettings& solver,
                             const ch10::MultigridStepperSettings& settings, int warmup,
                             int steps) {
  FewerWaitsStepper stepper(scene, solver, ch10::multigrid_params<FewerWaits>(settings));
  State state = rest_state(scene);
  std::vector<double> iterations;
  for (int k = 0; k < warmup + steps; ++k) {
    stepper.step(state);
    const StepProfile& p = stepper.profile();
    if (const char* why = divergence(state, p))
      throw std::runtime_error("diverged at step " + std::to_string(k + 1) + ": " + why);
    if (!p.converged)
      throw std::runtime_error("the solve did not converge at step " + std::to_string(k + 1));
    if (k >= warmup) iterations.push_back(p.cg_iterations);
  }
  IterationCost c;
  c.levels = stepper.preconditioner().multigrid().levels();
  c.median_iterations = median(iterations);
  double sum = 0.0;
  for (const double it : iterations) sum += it;
  c.mean_iterations = iterations.empty() ? 0.0 : sum / double(iterations.size());
  c.bytes_per_iteration = solve_bytes(stepper, scene, 1.0) - solve_bytes(stepper, scene, 0.0);
  c.bytes_per_step = solve_bytes(stepper, scene, c.mean_iterations);
  c.refreshes = stepper.preconditioner().multigrid().refresh_rule().refreshes();
  return c;
}

std::vector<Lesson> lessons() {
  Lesson iterations{"iterations",
                    "other multigrid settings in this chapter's solve: CG iterations and the "
                    "solve's bytes per iteration and per step",
                    "meshes/plate_poster.msh",
                    add_options,
                    [](const LessonRun& run) { return iterations_table(run); },
                    false};
  iterations.timed = false;
  iterations.record_args = {"--steps", "100"};
  return {iterations};
}

}  // namespace fem::ch13
