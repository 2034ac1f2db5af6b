// The library tests' body: the test beam (tests/support.hpp's cantilever scene, nodes at min x
// clamped, gravity -z) as the arrays an app gives the library.
#pragma once

#include "femcourse/simulator.hpp"
#include "support.hpp"

namespace fem::test {

inline femcourse::BodyDescription clamped_beam_description() {
  const fem::Scene scene = fem::test::test_scene("cantilever");
  femcourse::BodyDescription d;
  const auto& X = scene.mesh.X;
  d.rest_positions.assign(X.data(), X.data() + X.size());
  for (const auto& t : scene.mesh.tets)
    d.tetrahedra.insert(d.tetrahedra.end(), t.data(), t.data() + 4);
  for (const auto& c : scene.constraints) d.constraints.push_back({c.node});
  return d;
}

}  // namespace fem::test
