// Chapter 11: the orders are permutations that shrink the bandwidth, the renumbered scene is
// the same scene (the state maps in and out exactly, with the identity order chapter 11 is
// chapter 10 to the last bit), the interaction forces keep naming the caller's nodes, and
// the chapter matches chapter 01, allocates nothing and is bit-identical on 1, 2 and 3 threads.
#include <algorithm>
#include <numeric>

#include "catch2_compat.hpp"
#include "chapters/10_multigrid/stepper.hpp"
#include "chapters/11_node_order/stepper.hpp"
#include "common/threads.hpp"
#include "support.hpp"

using namespace fem;

FEM_CHAPTER_TESTS("11", "[ch11]")

namespace {

bool bit_identical(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return a.size() == b.size() && (a.array() == b.array()).all();
}

bool is_permutation(const ch11::NodeOrder& order, int n) {
  std::vector<int> sorted = order.old_of_new;
  std::sort(sorted.begin(), sorted.end());
  std::vector<int> expected(static_cast<std::size_t>(n));
  std::iota(expected.begin(), expected.end(), 0);
  if (sorted != expected || static_cast<int>(order.new_of_old.size()) != n) return false;
  for (int k = 0; k < n; ++k)
    if (order.new_of_old[order.old_of_new[k]] != k) return false;
  return true;
}

State moved_state(const Scene& scene) {
  State s = rest_state(scene);
  s.x += 1e-3 * Eigen::VectorXd::Random(s.x.size());
  s.v = Eigen::VectorXd::Random(s.v.size());
  return s;
}

}  // namespace

TEST_CASE("ch11: every order is a permutation, and RCM and Morton shrink the bandwidth", "[ch11]") {
  for (const std::string file : {"test_beam.msh", "plate_poster.msh"}) {
    const TetMesh mesh = load_mesh(test::mesh_path(file));
    const ch11::OrderQuality original = ch11::order_quality(mesh);
    for (const auto ordering :
         {ch11::Ordering::original, ch11::Ordering::rcm, ch11::Ordering::morton}) {
      const ch11::NodeOrder order = ch11::node_order(mesh, ordering);
      INFO(file << ", " << ch11::ordering_name(ordering));
      CHECK(is_permutation(order, mesh.num_nodes()));
      CHECK(order.identity() == (ordering == ch11::Ordering::original));
      Scene scene = make_scene("cantilever", mesh);
      const ch11::OrderQuality q = ch11::order_quality(ch11::renumbered(scene, order).mesh);
      INFO("bandwidth " << original.bandwidth << " -> " << q.bandwidth << ", element spread "
                        << original.element_spread << " -> " << q.element_spread);
      if (ordering == ch11::Ordering::original) {
        CHECK(q.bandwidth == original.bandwidth);
      } else {
        // gmsh numbers the surface first: an element's nodes lie far apart.
        CHECK(q.element_spread < 0.5 * original.element_spread);
        if (ordering == ch11::Ordering::rcm) CHECK(q.bandwidth < original.bandwidth / 2);
      }
    }
  }
}

TEST_CASE("ch11: the renumbered scene is the same scene under another naming", "[ch11]") {
  const Scene scene = test::driven_scene();
  const ch11::NodeOrder order = ch11::node_order(scene.mesh, ch11::Ordering::rcm);
  const Scene r = ch11::renumbered(scene, order);
  REQUIRE(r.mesh.num_tets() == scene.mesh.num_tets());
  for (int i = 0; i < scene.mesh.num_nodes(); ++i)
    CHECK(r.mesh.X.col(order.new_of_old[i]) == scene.mesh.X.col(i));
  // The same elements (as sets of renamed corners, each with its corner order), sorted.
  auto renamed = scene.mesh.tets;
  for (auto& t : renamed)
    for (int a = 0; a < 4; ++a) t[a] = order.new_of_old[t[a]];
  const auto less = [](const Eigen::Vector4i& a, const Eigen::Vector4i& b) {
    return std::lexicographical_compare(a.data(), a.data() + 4, b.data(), b.data() + 4);
  };
  auto a = renamed, b = r.mesh.tets;
  std::sort(a.begin(), a.end(), less);
  std::sort(b.begin(), b.end(), less);
  CHECK(a == b);
  REQUIRE(r.constraints.size() == scene.constraints.size());
  for (const NodeConstraint& c : scene.constraints) {
    const auto it =
        std::find_if(r.constraints.begin(), r.constraints.end(),
                     [&](const NodeConstraint& d) { return d.node == order.new_of_old[c.node]; });
    REQUIRE(it != r.constraints.end());
    CHECK(it->filter == c.filter);
    CHECK(it->target_velocity == c.target_velocity);
  }
}

TEST_CASE("ch11: with the identity order, chapter 11 is chapter 10 to the last bit", "[ch11]") {
  const Scene scene = test::driven_scene();
  ch10::MultigridStepper ten(scene, {});
  ch11::NodeOrderStepper::Params original;
  original.order.ordering = ch11::Ordering::original;
  ch11::NodeOrderStepper eleven(scene, {}, original);
  ten.team().adaptive_team().set_enabled(false);
  eleven.team().adaptive_team().set_enabled(false);
  State a = rest_state(scene), b = rest_state(scene);
  for (int k = 0; k < 30; ++k) {
    ten.step(a);
    eleven.step(b);
  }
  CHECK(bit_identical(a.x, b.x));
  CHECK(bit_identical(a.v, b.v));
}

TEST_CASE("ch11: the state maps in and out exactly, and forces keep the caller's node numbers",
          "[ch11]") {
  Scene scene = test::test_scene("cantilever");
  scene.gravity.setZero();
  // One step of chapter 11 against chapter 10 stepping the renumbered scene from the
  // renumbered state: the same numbers, named differently.
  const ch11::NodeOrder order = ch11::node_order(scene.mesh, ch11::Ordering::rcm);
  const Scene r = ch11::renumbered(scene, order);
  const int tip = scene.mesh.num_nodes() - 1;
  ch11::NodeOrderStepper eleven(scene, {});
  ch10::MultigridStepper ten(r, {});
  eleven.set_external_forces({{tip, Eigen::Vector3d(0.0, 1.0, 2.0)}});
  ten.set_external_forces({{order.new_of_old[tip], Eigen::Vector3d(0.0, 1.0, 2.0)}});
  CHECK(eleven.external_forces().coeff(3 * tip + 2) == 2.0);
  CHECK(eleven.external_forces().nonZeros() == 3);  // as chapter 10 stores it: x, y, z
  State mine = moved_state(scene), theirs = rest_state(r);
  for (int i = 0; i < scene.mesh.num_nodes(); ++i) {
    theirs.x.segment<3>(3 * order.new_of_old[i]) = mine.x.segment<3>(3 * i);
    theirs.v.segment<3>(3 * order.new_of_old[i]) = mine.v.segment<3>(3 * i);
  }
  // Chapter 11 sums the elements in slabs, chapter 10 in groups of 16: the same system up to
  // rounding, solved to the same tolerance from the same guess.
  eleven.step(mine);
  ten.step(theirs);
  double worst = 0.0;
  for (int i = 0; i < scene.mesh.num_nodes(); ++i)
    worst =
        std::max(worst, (mine.v.segment<3>(3 * i) - theirs.v.segment<3>(3 * order.new_of_old[i]))
                            .cwiseAbs()
                            .maxCoeff());
  INFO("largest velocity difference " << worst << " of speed " << mine.v.cwiseAbs().maxCoeff());
  CHECK(worst <= 1e-12 * mine.v.cwiseAbs().maxCoeff());
  CHECK_THROWS_AS(eleven.set_external_forces({{scene.mesh.num_nodes(), Eigen::Vector3d::Ones()}}),
                  std::invalid_argument);
}

TEST_CASE("ch11: the elements along the mesh form slabs that need few colours", "[ch11]") {
  const Scene scene = make_scene("cantilever", load_mesh(test::mesh_path("plate_poster.msh")));
  const ch11::NodeOrderStepper eleven(scene, {});
  const ch10::MultigridStepper ten(scene, {});
  INFO("colours: chapter 10 " << ten.elements().colours() << ", chapter 11 "
                              << eleven.elements().colours());
  CHECK(eleven.elements().colours() <= 8);
  CHECK(4 * eleven.elements().colours() < ten.elements().colours());
}

TEST_CASE("ch11: zero heap allocations per step after the first, with 2 threads", "[ch11]") {
  FEM_REQUIRE_ALLOCATION_COUNTER();
  const ThreadCountScope two(2);
  CHECK(test::allocations_per_step("11", test::driven_scene()) == 0);
}

TEST_CASE("ch11: constraints set while the body runs name the caller's nodes", "[ch11]") {
  // A node fixed at rest velocity stops where it is, to the bit (S_i = 0 and z_i = -v_i): in
  // the caller's numbering, although the step runs in the renumbered one.
  const Scene scene = test::test_scene("cantilever");
  ch11::NodeOrderStepper stepper(scene, {});
  REQUIRE(stepper.can_change_constraints());
  State state = rest_state(scene);
  for (int k = 0; k < 3; ++k) stepper.step(state);
  int node = scene.mesh.num_nodes() - 1;
  const auto constrained = [&](int n) {
    return std::any_of(scene.constraints.begin(), scene.constraints.end(),
                       [n](const NodeConstraint& c) { return c.node == n; });
  };
  while (constrained(node)) --node;
  REQUIRE(state.v.segment<3>(3 * node).norm() > 0.0);  // it was moving
  std::vector<NodeConstraint> held = scene.constraints;
  held.push_back(NodeConstraint::fixed(node));
  CHECK_THROWS_AS(stepper.set_constraints({NodeConstraint::fixed(scene.mesh.num_nodes())}),
                  std::invalid_argument);
  stepper.set_constraints(held);
  const Eigen::Vector3d at = state.x.segment<3>(3 * node);
  for (int k = 0; k < 3; ++k) stepper.step(state);
  CHECK(state.x.segment<3>(3 * node) == at);
  CHECK(state.v.segment<3>(3 * node).isZero(0.0));
  // Released, it moves again.
  stepper.set_constraints(scene.constraints);
  stepper.step(state);
  CHECK(state.x.segment<3>(3 * node) != at);
}
