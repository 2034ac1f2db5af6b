// The library's promises (femcourse/simulator.hpp): the chapter's own positions bit for bit,
// for any thread count; no heap allocation per step; bad arrays refused by name.
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/alloc_counter.hpp"
#include "common/stepper.hpp"
#include "femcourse/simulator.hpp"
#include "support.hpp"
#ifdef _OPENMP
#include <omp.h>
#endif

namespace {

using femcourse::Body;
using femcourse::BodyDescription;
using femcourse::Constraint;

// The test scene's body as arrays: what a user outside the course would write.
BodyDescription description_of(const fem::Scene& scene) {
  BodyDescription d;
  const auto& X = scene.mesh.X;
  d.rest_positions.assign(X.data(), X.data() + X.size());
  for (const auto& t : scene.mesh.tets)
    d.tetrahedra.insert(d.tetrahedra.end(), t.data(), t.data() + 4);
  d.youngs_modulus = scene.material.youngs_modulus;
  d.poisson_ratio = scene.material.poisson_ratio;
  d.density = scene.material.density;
  d.damping_alpha = scene.damping.alpha;
  d.damping_beta = scene.damping.beta;
  d.time_step = scene.dt;
  d.gravity = {scene.gravity.x(), scene.gravity.y(), scene.gravity.z()};
  for (const auto& c : scene.constraints) {
    REQUIRE(c.kind == fem::NodeConstraint::Kind::Fixed);
    d.constraints.push_back({c.node});
  }
  return d;
}

bool same_bits(const double* a, const Eigen::VectorXd& b) {
  return std::memcmp(a, b.data(), sizeof(double) * static_cast<std::size_t>(b.size())) == 0;
}

// The two-tetrahedron body of the refusal tests: nodes 0-3 and 1, 2, 3, 4.
BodyDescription two_tets() {
  BodyDescription d;
  d.rest_positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1};
  d.tetrahedra = {0, 1, 2, 3, 1, 4, 2, 3};
  d.constraints = {{0}};
  return d;
}

void refused_naming(const BodyDescription& d, const std::string& name) {
  try {
    Body body(d);
    FAIL("accepted; expected a refusal naming " + name);
  } catch (const std::invalid_argument& e) {
    INFO(e.what());
    CHECK(std::string(e.what()).find(name) != std::string::npos);
  }
}

}  // namespace

TEST_CASE("a body from arrays steps to the chapter's own positions, bit for bit", "[library]") {
  const fem::Scene scene = fem::test::test_scene("cantilever");
  // "" is the default, the last chapter: the one an app steps without naming one.
  for (const std::string chapter : {"01", "12", "13", ""}) {
    BodyDescription d = description_of(scene);
    d.chapter = chapter;
    Body body(d);
    const std::string id = chapter.empty() ? fem::latest_chapter().id : chapter;
    const fem::State expected = fem::test::run(id, scene, 20);
    for (int k = 0; k < 20; ++k) body.step();
    INFO("chapter " << id << (chapter.empty() ? " (the default)" : ""));
    CHECK(same_bits(body.positions(), expected.x));
    CHECK(same_bits(body.velocities(), expected.v));
    CHECK(body.time() == Approx(20 * scene.dt));
  }
}

TEST_CASE("the default chapter is the last one, and an unknown one is refused", "[library]") {
  BodyDescription d = description_of(fem::test::test_scene("cantilever"));
  CHECK(Body(d).chapter() == fem::latest_chapter().id);
  d.chapter = "99_nothing";
  CHECK_THROWS_AS(Body(d), std::invalid_argument);
}

TEST_CASE("a body is bit-identical on 1, 2 and 3 threads", "[library]") {
#ifdef _OPENMP
  BodyDescription d = description_of(fem::test::test_scene("cantilever"));
  std::vector<std::vector<double>> positions;
  for (int threads = 1; threads <= 3; ++threads) {
    d.threads = threads;
    Body body(d);
    for (int k = 0; k < 15; ++k) body.step();
    positions.emplace_back(body.positions(), body.positions() + 3 * body.num_nodes());
  }
  CHECK(positions[1] == positions[0]);
  CHECK(positions[2] == positions[0]);
#else
  SUCCEED("built without OpenMP: every body runs on one thread");
#endif
}

TEST_CASE("a step and a drag through the API allocate nothing", "[library]") {
  REQUIRE(fem::alloc::enabled());
  Body body(description_of(fem::test::test_scene("cantilever")));
  const std::vector<femcourse::NodeForce> drag = {{body.num_nodes() - 1, {0.0, 1.0, 2.0}},
                                                  {body.num_nodes() - 2, {0.0, 1.0, 2.0}}};
  body.set_forces(drag);  // the first drag sizes the storage
  body.step();
  fem::alloc::Scope scope;
  for (int k = 0; k < 10; ++k) {
    body.set_forces(drag);
    body.step();
  }
  body.set_forces({});
  body.step();
  CHECK(scope.allocations() == 0);
  CHECK(body.profile().allocations == 0);
  CHECK(body.profile().iterations > 0);
  CHECK(body.profile().converged);
}

TEST_CASE("a drag moves the body as the scene's forces do in the chapter's stepper", "[library]") {
  fem::Scene scene = fem::test::test_scene("cantilever");
  const int tip = scene.mesh.num_nodes() - 1;
  Body body(description_of(scene));
  body.set_forces({{tip, {0.0, 5.0, 0.0}}});
  scene.external_forces = {{tip, Eigen::Vector3d(0.0, 5.0, 0.0)}};
  const fem::State expected = fem::test::run(fem::latest_chapter().id, scene, 10);
  for (int k = 0; k < 10; ++k) body.step();
  CHECK(same_bits(body.positions(), expected.x));
  CHECK_THROWS_AS(body.set_forces({{-1, {0.0, 0.0, 1.0}}}), std::invalid_argument);
  CHECK_THROWS_AS(body.set_forces({{tip, {0.0, 0.0, NAN}}}), std::invalid_argument);
}

TEST_CASE("bad arrays are refused, naming the element or node", "[library]") {
  REQUIRE_NOTHROW(Body(two_tets()));
  BodyDescription d = two_tets();
  d.tetrahedra[6] = 7;
  refused_naming(d, "tetrahedron 1 refers to node 7");
  d = two_tets();
  std::swap(d.tetrahedra[5], d.tetrahedra[6]);
  refused_naming(d, "tetrahedron 1 is inverted");
  d.rest_positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0.5, 0.5, 0};
  d.tetrahedra = {0, 1, 2, 3, 0, 1, 2, 4};  // node 4 in the plane z = 0 of nodes 0, 1, 2
  refused_naming(d, "tetrahedron 1 is degenerate");
  d = two_tets();
  d.rest_positions[13] = NAN;
  refused_naming(d, "node 4 has a NaN");
  d = two_tets();
  d.rest_positions.insert(d.rest_positions.end(), {2, 2, 2});
  refused_naming(d, "node 5 belongs to no tetrahedron");
  d = two_tets();
  d.constraints = {{5}};
  refused_naming(d, "node 5, which does not exist");
  d.constraints = {{1, Constraint::Kind::Plane, {0.0, 0.0, 0.0}}};
  refused_naming(d, "node 1 has a zero direction");
  d.constraints = {{1}, {1}};
  refused_naming(d, "node 1 has two constraints");
  d = two_tets();
  d.rest_positions.pop_back();
  refused_naming(d, "not 3 per node");
  d = two_tets();
  d.poisson_ratio = 0.5;
  refused_naming(d, "Poisson");
}

TEST_CASE("a stepper of one's own plugs in", "[library]") {
  const BodyDescription d = description_of(fem::test::test_scene("cantilever"));
  int made = 0;
  Body own(d, [&made](const fem::Scene& scene, const fem::SolverSettings& settings) {
    ++made;
    return fem::make_stepper("06", scene, settings);
  });
  BodyDescription by_name = d;
  by_name.chapter = "06";
  Body reference(by_name);
  for (int k = 0; k < 5; ++k) {
    own.step();
    reference.step();
  }
  CHECK(made == 1);
  CHECK(own.chapter() == "custom");
  CHECK(std::memcmp(own.positions(), reference.positions(), sizeof(double) * 3 * own.num_nodes()) ==
        0);
}

TEST_CASE("a body from a gmsh file is the body of its arrays", "[library]") {
  const fem::Scene scene = fem::test::test_scene("cantilever");
  Body from_file =
      femcourse::body_from_gmsh_file(fem::test::mesh_path("test_beam.msh"), description_of(scene));
  Body from_arrays(description_of(scene));
  REQUIRE(from_file.num_nodes() == from_arrays.num_nodes());
  for (int k = 0; k < 5; ++k) {
    from_file.step();
    from_arrays.step();
  }
  CHECK(std::memcmp(from_file.positions(), from_arrays.positions(),
                    sizeof(double) * 3 * from_file.num_nodes()) == 0);
  CHECK_THROWS_AS(femcourse::body_from_gmsh_file("/nonexistent.msh", {}), fem::MeshError);
}

TEST_CASE("a diverging step throws StepDiverged, naming the step", "[library]") {
  BodyDescription d = description_of(fem::test::test_scene("cantilever"));
  d.youngs_modulus = 1e306;  // the system overflows (as fem_sim's test of it)
  Body body(d);
  try {
    body.step();
    FAIL("an overflowing step went through");
  } catch (const femcourse::StepDiverged& e) {
    CHECK(e.step == 1);
    CHECK(!e.reason.empty());
  }
}

TEST_CASE("a chapter switch continues from the state, as the viewer's does", "[library]") {
  const fem::Scene scene = fem::test::test_scene("cantilever");
  Body body(description_of(scene));
  for (int k = 0; k < 5; ++k) body.step();
  fem::State expected = body.state();
  body.set_chapter("11");
  CHECK(body.chapter() == fem::find_chapter("11").id);
  const auto stepper = fem::make_stepper("11", scene);
  for (int k = 0; k < 5; ++k) {
    body.step();
    stepper->step(expected);
  }
  CHECK(same_bits(body.positions(), expected.x));
  CHECK_THROWS_AS(body.set_chapter("99_nothing"), std::invalid_argument);
  CHECK(body.chapter() == fem::find_chapter("11").id);
  Body other(description_of(scene));
  other.set_state(body.state());
  CHECK(same_bits(other.positions(), body.state().x));
  fem::State wrong = body.state();
  wrong.x.conservativeResize(wrong.x.size() - 3);
  CHECK_THROWS_AS(other.set_state(wrong), std::invalid_argument);
}
