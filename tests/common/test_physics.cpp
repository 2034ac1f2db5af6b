// The physics of the step, checked on the reference stepper (chapter 01): momentum,
// energy, constraints. Every other chapter is checked against chapter 01.
#include "catch2_compat.hpp"
#include "common/model.hpp"
#include "support.hpp"

using namespace fem;

namespace {

// A free-floating body (no constraints, no gravity) with a stretched initial shape and
// a random initial velocity: something for the elastic forces to do.
Scene free_scene(const RayleighDamping& damping) {
  Scene s = test::test_scene("cantilever");
  s.constraints.clear();
  s.gravity.setZero();
  s.damping = damping;
  return s;
}

State perturbed_state(const Scene& scene) {
  State state = rest_state(scene);
  for (int i = 0; i < scene.mesh.num_nodes(); ++i) state.x[3 * i] *= 1.1;  // 10% stretch in x
  std::srand(7);
  state.v = 0.1 * Eigen::VectorXd::Random(state.v.size());
  return state;
}

Eigen::Vector3d momentum(const Model& model, const Eigen::VectorXd& v) {
  const Eigen::VectorXd p = model.lumped_mass.cwiseProduct(v);
  return Eigen::Map<const Eigen::Matrix3Xd>(p.data(), 3, model.num_nodes).rowwise().sum();
}

double total_energy(const Model& model, const Scene& scene, const State& state) {
  return 0.5 * state.v.dot(model.lumped_mass.cwiseProduct(state.v)) +
         elastic_energy(model, scene, state.x);
}

}  // namespace

TEST_CASE("no gravity, no constraints: linear momentum is conserved", "[physics]") {
  // Rayleigh stiffness damping (beta K) conserves momentum, mass damping (alpha M)
  // does not: it is a drag against the world frame. So alpha = 0 here.
  const Scene scene = free_scene({0.0, 0.01});
  const Model model(scene);
  SolverSettings tight;
  tight.tolerance = 1e-12;
  auto stepper = make_stepper("01", scene, tight);
  State state = perturbed_state(scene);
  const Eigen::Vector3d p0 = momentum(model, state.v);
  const double scale = model.lumped_mass.dot(state.v.cwiseAbs());  // sum of |m v|
  for (int k = 0; k < 30; ++k) stepper->step(state);
  CHECK((momentum(model, state.v) - p0).norm() < 1e-9 * scale);
  // ... and the body really moved: the test is not vacuous.
  CHECK((state.x - rest_state(scene).x).norm() > 0.1);
}

TEST_CASE("with damping the total energy decreases every step", "[physics]") {
  const Scene scene = free_scene({0.5, 0.01});
  const Model model(scene);
  SolverSettings tight;
  tight.tolerance = 1e-10;
  auto stepper = make_stepper("01", scene, tight);
  State state = perturbed_state(scene);
  double energy = total_energy(model, scene, state);
  const double initial = energy;
  for (int k = 0; k < 40; ++k) {
    stepper->step(state);
    const double next = total_energy(model, scene, state);
    CHECK(next < energy);
    energy = next;
  }
  CHECK(energy < 0.5 * initial);
}

TEST_CASE("constraints: fixed nodes stay, plane and line nodes stay on their plane and line",
          "[physics]") {
  const Scene scene = test::test_scene("sliding");
  int fixed = 0, plane = 0, line = 0;
  for (const auto& c : scene.constraints) {
    fixed += c.kind == NodeConstraint::Kind::Fixed;
    plane += c.kind == NodeConstraint::Kind::Plane;
    line += c.kind == NodeConstraint::Kind::Line;
  }
  REQUIRE(fixed == 1);  // every filter case occurs in this scene
  REQUIRE(plane > 0);
  REQUIRE(line > 0);
  REQUIRE_FALSE(scene.external_forces.empty());

  const State state = test::run("01", scene, 50);
  const State rest = rest_state(scene);
  const double floor = scene.mesh.X.row(2).minCoeff(), side = scene.mesh.X.row(1).minCoeff();
  for (const auto& c : scene.constraints) {
    const Eigen::Vector3d x = state.x.segment<3>(3 * c.node);
    const Eigen::Vector3d X = rest.x.segment<3>(3 * c.node);
    switch (c.kind) {
      case NodeConstraint::Kind::Fixed:
        CHECK((x - X).norm() == 0.0);
        break;
      case NodeConstraint::Kind::Plane:
        CHECK(std::abs(x.z() - floor) < 1e-9);
        break;
      case NodeConstraint::Kind::Line:
        CHECK(std::abs(x.z() - floor) < 1e-9);
        CHECK(std::abs(x.y() - side) < 1e-9);
        break;
    }
  }
  // The push moved the free nodes: the constraints held against a real load.
  CHECK((state.x - rest.x).cwiseAbs().maxCoeff() > 1e-3);
}

TEST_CASE("a driven node follows its prescribed velocity", "[physics]") {
  Scene scene = test::test_scene("cantilever");
  const Eigen::Vector3d velocity(0.0, 0.0, 0.2);
  for (auto& c : scene.constraints) c.target_velocity = velocity;  // lift the clamp
  const int steps = 20;
  const State state = test::run("01", scene, steps);
  for (const auto& c : scene.constraints) {
    const Eigen::Vector3d moved = state.x.segment<3>(3 * c.node) - scene.mesh.X.col(c.node);
    CHECK((moved - steps * scene.dt * velocity).norm() < 1e-12);
  }
}
