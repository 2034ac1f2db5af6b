// The markers the viewer draws over the body, one colour each: the renderer draws them and
// the panel's legend explains them, from this one table.
#pragma once

#include <array>

#include "common/scene.hpp"

namespace fem::viewer {

struct Marker {
  std::array<float, 3> rgb;
  const char* meaning;
};

inline Marker constraint_marker(NodeConstraint::Kind kind) {
  switch (kind) {
    case NodeConstraint::Kind::Fixed:
      return {{0.85f, 0.15f, 0.15f}, "fixed node (S_i = 0)"};
    case NodeConstraint::Kind::Line:
      return {{0.95f, 0.55f, 0.10f}, "node on a line (one free direction)"};
    case NodeConstraint::Kind::Plane:
      return {{0.20f, 0.45f, 0.90f}, "node in a plane (two free directions)"};
  }
  return {{1.0f, 1.0f, 1.0f}, "constrained node"};
}

inline const Marker kSpringMarker{{1.0f, 0.85f, 0.1f}, "mouse spring: grabbed node, cursor"};

}  // namespace fem::viewer
