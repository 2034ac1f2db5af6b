// Each chapter placed under the roofs: its step measured phase by phase, its work counted,
// and the time the roofs allow each phase.
#pragma once

#include <string>
#include <vector>

#include "apps/roofline/roofs.hpp"
#include "chapters/registry.hpp"
#include "chapters/work.hpp"

namespace fem::roofline {

struct PhasePoint {
  PhaseWork work;
  std::string level;          // where its working set fits: "L1", ..., "memory", or "L2+L3"
  double bound_s = 0.0;       // max(memory_s, arithmetic_s) + waiting_s (roofs.hpp: held_by)
  double memory_s = 0.0;      // its bytes (or its parts') at the roofs of their levels
  double arithmetic_s = 0.0;  // its flops at the peaks
  double regions = 0.0, barriers = 0.0;  // its synchronizations per measured step (measured)
  double waiting_s = 0.0;   // those at their measured costs on the team each step ran on
  double measured_s = 0.0;  // the median of the measured steps
};

// One chapter at one thread count under the roofs.
struct PlacedRun {
  std::string mesh, chapter;
  int nodes = 0, tets = 0, threads = 1;
  double iterations = 0.0;  // median CG iterations
  ExecutedWork executed;    // what the stepper's counters say ran, per measured step
  int team_min = 0,
      team_max = 0;  // threads the measured steps ran on (0: the stepper does not say)
  std::vector<PhasePoint> phases;
  double step_s = 0.0;                   // median step
  double bound_s = 0.0;                  // sum of the phases' bounds
  double regions = 0.0, barriers = 0.0;  // the step's synchronizations per measured step
  double waiting_s = 0.0;  // those at their measured costs: the sum of the phases' waiting
};

// `chapter` on `scene` under each of `roofs` (one per thread count; a chapter that does not
// use threads only under the one-thread roofs): `warmup` steps, then `steps` measured, medians
// per phase, its work counted by the chapter's own hook (CourseChapter::work; a chapter without
// one is measured and not counted). A fresh stepper at each count, as fem_bench's runs.
std::vector<PlacedRun> place_chapter(const ChapterInfo& chapter, const Scene& scene,
                                     const std::vector<Roofs>& roofs, int warmup, int steps);

}  // namespace fem::roofline
