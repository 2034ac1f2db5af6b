// divergence(): the rule that turns a step into a failure the programs stop on. A solve
// that did not converge by far (nu = 0.49999999: CG at its cap with a relative residual
// above 1) is reported as clearly as a NaN; a capped solve close to the tolerance is not.
#include <string>

#include "catch2_compat.hpp"
#include "support.hpp"

using namespace fem;

namespace {

StepProfile solve_that(bool converged, double relative_residual) {
  StepProfile p;
  p.converged = converged;
  p.relative_residual = relative_residual;
  p.cg_iterations = 2000;
  return p;
}

}  // namespace

TEST_CASE("divergence: a capped solve is a failed step only when worse than no solve",
          "[divergence]") {
  const State state = rest_state(test::test_scene("cantilever"));
  CHECK(divergence(state, solve_that(true, 1e-5)) == nullptr);
  CHECK(divergence(state, solve_that(false, 2e-4)) == nullptr);  // inexact: warned, counted
  CHECK(divergence(state, solve_that(false, 0.99)) == nullptr);
  const char* why = divergence(state, solve_that(false, 250.0));
  REQUIRE(why != nullptr);
  CHECK(std::string(why).find("did not converge") != std::string::npos);
  // A residual above 1 that met the tolerance cannot happen; the flag alone does not fail it.
  CHECK(divergence(state, solve_that(true, 2.0)) == nullptr);
}

TEST_CASE("divergence: nu = 0.49999999 fails the first step in every chapter", "[divergence]") {
  // (Near nu = 0.5 the system's condition number grows without bound; a nu this close fails
  // even the strongest preconditioner's first step within the iteration cap.)
  Material nearly_incompressible;
  nearly_incompressible.youngs_modulus = 2e5;
  nearly_incompressible.poisson_ratio = 0.49999999;
  nearly_incompressible.density = 1000.0;
  Scene scene = make_scene("cantilever", test::test_mesh(), nearly_incompressible);
  scene.dt = 0.01;
  SolverSettings capped;
  capped.max_iterations = 500;  // the failure is the same at the default 2000, four times slower
  for (const ChapterInfo& chapter : chapters()) {
    auto stepper = chapter.make(scene, capped);
    State state = rest_state(scene);
    stepper->step(state);
    const StepProfile& p = stepper->profile();
    INFO(chapter.id << ": " << p.cg_iterations << " iterations, relative residual "
                    << p.relative_residual);
    CHECK_FALSE(p.converged);
    CHECK(state.x.allFinite());  // finite, so only the residual tells
    CHECK((divergence(state, p) != nullptr) == (p.relative_residual > 1.0));
    if (chapter.id < "10") CHECK(p.relative_residual > 1.0);
  }
}
