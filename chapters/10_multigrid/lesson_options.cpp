// Chapter 10's lesson options: `fem_lessons multigrid`'s command line, its defaults the
// chapter's (MultigridStepperSettings{}), and the settings it asks for (see lesson.hpp).
#include "chapters/10_multigrid/lesson_options.hpp"

#include <cstdlib>
#include <sstream>
#include <string>

#include "common/threads.hpp"

namespace fem::ch10 {

namespace {

Smoother smoother_from(const std::string& name) {
  if (name == "gs") return Smoother::GaussSeidel;
  if (name == "chebyshev") return Smoother::Chebyshev;
  if (name == "jacobi") return Smoother::Jacobi;
  throw UsageError("--smoother must be gs, chebyshev or jacobi");
}

const char* smoother_name(Smoother smoother) {
  switch (smoother) {
    case Smoother::GaussSeidel:
      return "gs";
    case Smoother::Chebyshev:
      return "chebyshev";
    default:
      return "jacobi";
  }
}

}  // namespace

MultigridStepperSettings multigrid_from_args(const ArgParser& args) {
  MultigridStepperSettings settings;
  MultigridSettings& s = settings.multigrid;
  CoarseningSettings& c = s.coarsening;
  SmootherSettings& r = s.relax;
  c.modes = args.get_int("modes");
  r.smoother = smoother_from(args.get("smoother"));
  r.sweeps = args.get_int("sweeps");
  r.l1 = args.get("l1") != "off";
  settings.extrapolation = args.get_int("extrapolate");
  s.rows.max_blocks = args.get_int("blocks");
  s.rows.serial_rows = args.get_int("serial-rows");
  r.chebyshev_degree = args.get_int("degree");
  c.improve_candidates = args.get_int("improve");
  c.power_iterations = args.get_int("power");
  const std::string prolongator = args.get("prolongator");
  if (prolongator != "every-step" && prolongator != "frozen" && prolongator != "tentative")
    throw UsageError("--prolongator must be frozen, every-step or tentative");
  c.smooth_prolongator = prolongator != "tentative";
  c.update_prolongator = prolongator == "every-step";
  s.max_coarse_dofs = args.get_int("max-coarse");
  s.refresh.every = args.get_int("coarse-every");
  s.refresh.growth = args.get_double("growth");
  if (args.get("l1") != "on" && args.get("l1") != "off") throw UsageError("--l1 must be on or off");
  try {
    check(settings);  // the stepper's own rule: one place says what is allowed
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  return settings;
}

// The options' defaults are the chapter's (MultigridStepperSettings{}).
void add_multigrid_options(ArgParser& args) {
  const MultigridStepperSettings defaults;
  const MultigridSettings& d = defaults.multigrid;
  const auto text = [](auto value) {
    std::ostringstream s;
    s << value;
    return s.str();
  };
  add_solver_options(args);
  args.option("modes", "N", "near-null-space modes per aggregate: 6 or 3 (translations)",
              text(d.coarsening.modes));
  args.option("smoother", "NAME",
              "gs (l1-hybrid block Gauss-Seidel), chebyshev (on block Jacobi) or jacobi",
              smoother_name(d.relax.smoother));
  args.option("sweeps", "N", "pre- and post-smoothing sweeps", text(d.relax.sweeps));
  args.option("l1", "on|off", "Gauss-Seidel: the l1 term on the couplings between row blocks",
              d.relax.l1 ? "on" : "off");
  args.option("blocks", "N", "at most N fixed row blocks per level (1: sequential Gauss-Seidel)",
              text(d.rows.max_blocks));
  args.option("serial-rows", "N", "levels of fewer rows run on one thread",
              text(d.rows.serial_rows));
  args.option("degree", "N", "Chebyshev: the polynomial's degree", text(d.relax.chebyshev_degree));
  args.option("power", "N", "power iterations of the first estimate of rho(D^-1 A) on each level",
              text(d.coarsening.power_iterations));
  args.option("improve", "N", "symmetric Gauss-Seidel sweeps on the rigid-body modes at set-up",
              text(d.coarsening.improve_candidates));
  args.option("extrapolate", "ORDER",
              "the guess: 0 the last solution, 1 the line through the last two, 2 the parabola "
              "through the last three",
              text(defaults.extrapolation));
  args.option("prolongator", "KIND",
              "frozen (smoothed on the first step), every-step (smoothed at every refresh) or "
              "tentative (unsmoothed)",
              d.coarsening.update_prolongator   ? "every-step"
              : d.coarsening.smooth_prolongator ? "frozen"
                                                : "tentative");
  args.option("max-coarse", "N", "largest level solved by dense Cholesky, in unknowns",
              text(d.max_coarse_dofs));
  args.option("coarse-every", "K", "recompute the coarse matrices every K-th step",
              text(d.refresh.every));
  args.option("growth", "G",
              "and earlier when a solve takes more than G times the V-cycles after the last "
              "refresh (0: never)",
              text(d.refresh.growth));
  args.option("export", "DIR", "write the last filtered system as Matrix Market into DIR", "");
  args.option("cost-threads", "LIST",
              "thread counts of the cost table, comma-separated (default: 1 and --threads)", "");
}

}  // namespace fem::ch10
