// What a step can do to the body that the step cannot describe, told apart from what an
// ordinary run does. An ordinary swing moves nodes far (the tip of a cantilever travels
// further than the body is long when it swings down) and may turn one element of a coarse
// mesh inside out for a step or two: neither is trouble, and a warning there would teach the
// reader to ignore warnings. Trouble is what persists or grows:
//   - elements that stay inverted (det F <= 0) step after step: the body folds through itself;
//   - an element stretched to several times its rest size: the run has blown up (rotation
//     leaves edge lengths alone, so a swing never looks like this);
//   - energy that grows: kinetic plus elastic plus gravity's potential, which damping and the
//     implicit step only ever take away (in a scene whose constraints move nothing and with no
//     external forces; where they do work, the check is left out).
// The corotated model returns finite numbers in all three cases (its rotation is proper also
// for inverted elements), so a check of finiteness alone would stay silent.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "common/model.hpp"
#include "common/scene.hpp"

namespace fem {

struct DeformationCheck {
  int inverted = 0;  // tetrahedra with det(F) <= 0 (det Ds <= 0: det Dm > 0 on load)
  int elements = 0;
  double largest_stretch = 1.0;  // max over edges of deformed length / rest length
  double energy = 0.0;           // kinetic + elastic + gravity's potential (0 at rest) [J]
  double energy_content = 0.0;   // kinetic + elastic [J]: the scale the growth is measured on
  double energy_noise = 0.0;     // gravity's potential to its last digits [J]: no growth below
};

// The thresholds, from the course's scenes (the default cantilever, 200 steps on the poster's
// plate; the regime sweep's bodies over E, 18 steps): none of them reaches one.
struct DeformationLimits {
  // Inverted elements: a few of a coarse mesh turn over for a while in an ordinary swing (one
  // of the plate's 5934, for 19 steps, in the default cantilever at E = 1e5); trouble is a share
  // of the body inverted step after step, or inverted elements that never recover.
  double inverted_share = 0.01;  // of the elements, ...
  int inverted_share_steps = 3;  // ... for this many consecutive steps
  int inverted_steps = 50;       // any inverted element, for this many consecutive steps
  double stretch = 5.0;          // an edge at 5 times its rest length (the course: under 3)
  double energy_growth = 0.05;   // energy above rest by 5% of the largest energy content
};

// Measures one state of the scene (x, v stacked: node i at 3i..3i+2).
class DeformationProbe {
 public:
  explicit DeformationProbe(const Scene& scene);
  DeformationCheck check(const State& state) const;

 private:
  const Scene& scene_;
  Model model_;
  std::vector<double> rest_edges_;  // 6 per tetrahedron
  bool energy_balance_ = true;      // false when constraints or external forces do work
};

// Counts a run's trouble and warns once per kind, when it is trouble, with advice.
class DeformationReport {
 public:
  explicit DeformationReport(DeformationLimits limits = {}) : limits_(limits) {}
  // Returns true when this step raised a warning (printed on stderr).
  bool after_step(int step, const DeformationCheck& check);
  void summary(int steps) const;
  int troubled_steps() const { return troubled_steps_; }

 private:
  DeformationLimits limits_;
  int inverted_run_ = 0, share_run_ = 0, troubled_steps_ = 0;
  double largest_content_ = 0.0;
  bool warned_inverted_ = false, warned_stretch_ = false, warned_energy_ = false;
};

}  // namespace fem
