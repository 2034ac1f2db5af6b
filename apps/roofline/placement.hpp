// Each chapter placed under the roofs: its step measured phase by phase, its work counted,
// and the time the roofs allow each phase.
#pragma once

#include <string>
#include <vector>

#include "apps/roofline/roofs.hpp"
#include "apps/roofline/work.hpp"
#include "chapters/registry.hpp"

namespace fem::roofline {

struct PhasePoint {
  PhaseWork work;
  std::string level;        // where its working set fits: "L1", ..., "memory"
  double bound_s = 0.0;     // bound_seconds
  double measured_s = 0.0;  // the median of the measured steps
};

struct ChapterRun {
  std::string mesh, chapter, counted_as;
  int nodes = 0, tets = 0, threads = 1;
  double iterations = 0.0;  // median CG iterations
  std::vector<PhasePoint> phases;
  double step_s = 0.0;   // median step
  double bound_s = 0.0;  // sum of the phases' bounds
};

// `chapter` on `scene` under each of `roofs` (one per thread count; a chapter that does not
// use threads only under the one-thread roofs): `warmup` steps, then `steps` measured, medians
// per phase. The same stepper at each count, in the order given.
std::vector<ChapterRun> place_chapter(const ChapterInfo& chapter, const Scene& scene,
                                      const std::vector<Roofs>& roofs, int warmup, int steps);

}  // namespace fem::roofline
