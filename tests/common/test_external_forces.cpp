// Stepper::set_external_forces: the interaction forces can change between steps (the
// viewer's mouse spring), in every chapter, with the same effect as a scene that had
// them from the start.
#include <cmath>

#include "common/alloc_counter.hpp"
#include "support.hpp"

using namespace fem;

namespace {

std::vector<ExternalForce> pull_on_the_tip(const Scene& scene) {
  int tip = 0;
  for (int i = 0; i < scene.mesh.num_nodes(); ++i)
    if (scene.mesh.X(0, i) > scene.mesh.X(0, tip)) tip = i;
  return {{tip, Eigen::Vector3d(0.0, 0.5, 2.0)}, {tip, Eigen::Vector3d(0.0, 0.5, 0.0)}};
}

}  // namespace

TEST_CASE("forces set after construction act like the scene's own, in every chapter",
          "[external]") {
  const Scene plain = test::test_scene("cantilever");
  Scene pulled = plain;
  pulled.external_forces = pull_on_the_tip(plain);

  for (const ChapterInfo& chapter : chapters()) {
    auto from_scene = chapter.make(pulled, test::tight_solver());
    auto set_later = chapter.make(plain, test::tight_solver());
    set_later->set_external_forces(pulled.external_forces);
    State a = rest_state(plain), b = rest_state(plain);
    for (int k = 0; k < 20; ++k) {
      from_scene->step(a);
      set_later->step(b);
    }
    INFO(chapter.id);
    CHECK((a.x - b.x).cwiseAbs().maxCoeff() == 0.0);  // the same arithmetic, bit for bit

    // The pull changes the motion: the test would catch forces that are ignored.
    const State unpulled = test::run(chapter.id, plain, 20, test::tight_solver());
    CHECK((unpulled.x - a.x).cwiseAbs().maxCoeff() > 1e-4);
  }
}

TEST_CASE("forces on the same node add up, and clearing them removes them", "[external]") {
  const Scene scene = test::test_scene("cantilever");
  auto stepper = make_stepper("01", scene);
  const auto forces = pull_on_the_tip(scene);
  stepper->set_external_forces(forces);
  const int tip = forces[0].node;
  CHECK(stepper->external_forces().nonZeros() == 3);
  CHECK(stepper->external_forces().coeff(3 * tip + 1) == 1.0);
  CHECK(stepper->external_forces().coeff(3 * tip + 2) == 2.0);
  stepper->set_external_forces({});
  CHECK(stepper->external_forces().nonZeros() == 0);
  CHECK(stepper->external_forces().size() == 3 * scene.mesh.num_nodes());
}

TEST_CASE("bad external forces are refused with the reason", "[external]") {
  const Scene scene = test::test_scene("cantilever");
  auto stepper = make_stepper("06", scene);
  const int n = scene.mesh.num_nodes();
  CHECK_THROWS_WITH(stepper->set_external_forces({{n, Eigen::Vector3d::UnitZ()}}),
                    test::contains_text("not in [0, " + std::to_string(n) + ")"));
  CHECK_THROWS_WITH(stepper->set_external_forces({{-1, Eigen::Vector3d::UnitZ()}}),
                    test::contains_text("node -1"));
  CHECK_THROWS_WITH(stepper->set_external_forces({{0, Eigen::Vector3d(std::nan(""), 0.0, 0.0)}}),
                    test::contains_text("not finite"));
}

TEST_CASE("moving the spring from node to node allocates nothing once the storage is sized",
          "[external]") {
  FEM_REQUIRE_ALLOCATION_COUNTER();
  const Scene scene = test::test_scene("cantilever");
  auto stepper = make_stepper("07", scene);
  stepper->set_external_forces({{0, Eigen::Vector3d::UnitZ()}, {1, Eigen::Vector3d::UnitY()}});
  std::vector<ExternalForce> moved = {{5, Eigen::Vector3d::UnitX()}, {7, Eigen::Vector3d::UnitZ()}};
  alloc::Scope scope;
  stepper->set_external_forces(moved);
  CHECK(scope.allocations() == 0);
}
