// The viewer's simulation side, without a window: camera rays, picking, the mouse spring,
// chapter switching with the state carried over, and the scripted drag.
#include "apps/viewer/camera.hpp"
#include "apps/viewer/controls.hpp"
#include "apps/viewer/picking.hpp"
#include "apps/viewer/session.hpp"
#include "chapters/registry.hpp"
#include "support.hpp"

using namespace fem;
using namespace fem::viewer;

namespace {

SessionSettings test_settings() {
  SessionSettings s;
  s.material = test::test_scene("cantilever").material;
  s.solver = test::tight_solver();
  return s;
}

OrbitCamera framed_camera(const TetMesh& mesh) {
  OrbitCamera camera;
  camera.frame(Eigen::AlignedBox3d(mesh.X.rowwise().minCoeff(), mesh.X.rowwise().maxCoeff()));
  return camera;
}

}  // namespace

TEST_CASE("a pixel's ray passes through the points that project to that pixel", "[viewer]") {
  OrbitCamera camera;
  camera.frame(Eigen::AlignedBox3d(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0.2, 0.1)));
  const Eigen::Vector3d p(0.8, 0.1, 0.05);
  const Eigen::Vector2d pixel = camera.project(p, 800, 600);
  const Ray ray = camera.ray(pixel.x(), pixel.y(), 800, 600);
  const Eigen::Vector3d to_p = p - ray.origin;
  // The ray's direction is the direction to p (float matrices in project: 1e-5).
  CHECK((to_p.normalized() - ray.direction).norm() < 1e-5);
  // The window's centre looks at the target.
  const Ray centre = camera.ray(400, 300, 800, 600);
  CHECK((centre.direction - camera.forward()).norm() < 1e-12);
}

TEST_CASE("the ray from the camera through a surface point picks a node of that face", "[viewer]") {
  const TetMesh mesh = test::test_mesh();
  const OrbitCamera camera = framed_camera(mesh);
  const Eigen::VectorXd x = Eigen::Map<const Eigen::VectorXd>(mesh.X.data(), mesh.X.size());
  const Eigen::Vector3i& face = mesh.boundary.front();
  const Eigen::Vector3d centre =
      (mesh.X.col(face[0]) + mesh.X.col(face[1]) + mesh.X.col(face[2])) / 3.0;
  const Ray ray{camera.eye(), (centre - camera.eye()).normalized()};
  const std::optional<SurfaceHit> hit = pick_surface(ray, x, mesh.boundary);
  REQUIRE(hit);
  // Either this face or one in front of it: never farther than the face itself.
  CHECK(hit->distance <= (centre - camera.eye()).norm() + 1e-9);
  CHECK(hit->node >= 0);
  CHECK(hit->node < mesh.num_nodes());

  const Ray away{camera.eye(), -camera.forward()};  // looking away from the body
  CHECK_FALSE(pick_surface(away, x, mesh.boundary));
}

TEST_CASE("a ray meets a triangle where the algebra says", "[viewer]") {
  const Ray ray{Eigen::Vector3d(0.25, 0.25, 1.0), Eigen::Vector3d(0, 0, -1)};
  const auto t = intersect_triangle(ray, Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0),
                                    Eigen::Vector3d(0, 1, 0));
  REQUIRE(t);
  CHECK(*t == Approx(1.0));
  const Ray outside{Eigen::Vector3d(0.75, 0.75, 1.0), Eigen::Vector3d(0, 0, -1)};
  CHECK_FALSE(intersect_triangle(outside, Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0),
                                 Eigen::Vector3d(0, 1, 0)));
  const Ray behind{Eigen::Vector3d(0.25, 0.25, -1.0), Eigen::Vector3d(0, 0, -1)};
  CHECK_FALSE(intersect_triangle(behind, Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0),
                                 Eigen::Vector3d(0, 1, 0)));
}

TEST_CASE("the mouse spring pulls the patch towards the target with the capped stiffness",
          "[viewer]") {
  Session session(test::test_mesh(), test_settings(), "06");
  const Eigen::Index tip = [&] {
    Eigen::Index i;
    session.scene().mesh.X.row(0).maxCoeff(&i);
    return i;
  }();
  const Eigen::Vector3d at = session.state().x.segment<3>(3 * tip);
  session.grab(static_cast<int>(tip), at + Eigen::Vector3d(0, 0, 0.1));
  const std::vector<ExternalForce> forces = session.spring_forces();
  REQUIRE(forces.size() > 1);  // a patch, not one node
  Eigen::Vector3d total = Eigen::Vector3d::Zero();
  for (const ExternalForce& f : forces) total += f.force;
  CHECK(total.head<2>().norm() < 1e-12 * total.norm());  // straight up
  CHECK(total.z() > 0.0);

  // Pulled up, the tip ends above where the cantilever alone would take it.
  Session alone(test::test_mesh(), test_settings(), "06");
  for (int k = 0; k < 30; ++k) {
    REQUIRE(session.step());
    REQUIRE(alone.step());
  }
  CHECK(session.state().x[3 * tip + 2] > alone.state().x[3 * tip + 2] + 1e-3);

  session.release();
  CHECK(session.spring_forces().empty());
}

TEST_CASE("the spring's stiffness is capped where the explicit force stays stable", "[viewer]") {
  CHECK(spring_stiffness(100.0, 2.0, 1.0, 0.01) == Approx(200.0));  // below the cap
  CHECK(spring_stiffness(100.0, 200.0, 1.0, 0.01) == Approx(1e4));  // m / h^2
}

TEST_CASE("switching chapters keeps the state and continues the same motion", "[viewer]") {
  Session session(test::test_mesh(), test_settings(), "01");
  for (int k = 0; k < 10; ++k) session.step();
  const State before = session.state();
  session.set_chapter("07");
  CHECK(session.chapter() == "07_block_sparse");
  CHECK(session.state().x == before.x);
  CHECK(session.time() == Approx(0.1));
  for (int k = 0; k < 10; ++k) session.step();

  Session reference(test::test_mesh(), test_settings(), "01");
  for (int k = 0; k < 20; ++k) reference.step();
  const double motion = (reference.state().x - rest_state(reference.scene()).x).norm();
  CHECK((session.state().x - reference.state().x).norm() < 1e-8 * motion);
  CHECK(session.history().size() == 10);  // the panel's history restarts with the chapter
}

TEST_CASE("new material keeps the state, and a new scene starts from rest", "[viewer]") {
  Session session(test::test_mesh(), test_settings(), "05");
  for (int k = 0; k < 5; ++k) session.step();
  const State moved = session.state();
  SessionSettings stiffer = session.settings();
  stiffer.material.youngs_modulus *= 10.0;
  session.apply(stiffer);
  CHECK(session.state().x == moved.x);
  CHECK(session.scene().material.youngs_modulus == stiffer.material.youngs_modulus);

  SessionSettings sliding = session.settings();
  sliding.scene = "sliding";
  session.apply(sliding);
  CHECK(session.scene().name == "sliding");
  CHECK(session.state().x == rest_state(session.scene()).x);
  CHECK(session.time() == 0.0);

  SessionSettings bad = session.settings();
  bad.dt = -1.0;
  CHECK_THROWS_AS(session.apply(bad), std::invalid_argument);
  CHECK(session.settings().dt > 0.0);  // nothing changed
}

TEST_CASE("a target far away or not finite cannot fling the body", "[viewer]") {
  Session session(test::test_mesh(), test_settings(), "07");
  const Eigen::Vector3d at = session.state().x.head<3>();
  session.grab(0, at + Eigen::Vector3d(1e300, 0, 0));  // a ray that grazes the drag plane
  const auto far = session.spring_forces();
  session.grab(0, at + Eigen::Vector3d(10.0 * kMaxPull, 0, 0));  // also beyond the cap
  Eigen::Vector3d total_far = Eigen::Vector3d::Zero(), total_limit = Eigen::Vector3d::Zero();
  for (const ExternalForce& f : far) total_far += f.force;
  for (const ExternalForce& f : session.spring_forces()) total_limit += f.force;
  CHECK(total_far.allFinite());
  CHECK(total_far.norm() == Approx(total_limit.norm()));  // both at the longest pull
  for (int k = 0; k < 5; ++k) REQUIRE(session.step());
  CHECK(session.state().x.allFinite());
  CHECK_THROWS_AS(session.grab(0, Eigen::Vector3d(NAN, 0, 0)), std::invalid_argument);
  session.move_grab(Eigen::Vector3d(INFINITY, 0, 0));  // ignored: the target stays finite
  CHECK(session.grabbed()->target.allFinite());
}

TEST_CASE("the scripted drag refuses what it cannot replay", "[viewer]") {
  CHECK_NOTHROW(DragReplay::parse("auto", 60));
  CHECK_NOTHROW(DragReplay::parse("0.5,0.5,0.5,0.2", 60));
  CHECK_THROWS_WITH(DragReplay::parse("0.5,0.5", 60), test::contains_text("x0,y0,x1,y1"));
  CHECK_THROWS_WITH(DragReplay::parse("0.5,0.5,2,0", 60), test::contains_text("[0, 1]"));
  CHECK_THROWS_WITH(DragReplay::parse("a,b,c,d", 60), test::contains_text("not a number"));
}

TEST_CASE("the scripted drag through the mouse controls grabs the body and pulls it up",
          "[viewer]") {
  Session session(test::test_mesh(), test_settings(), "07");
  OrbitCamera camera = framed_camera(session.scene().mesh);
  DragReplay replay = DragReplay::parse("auto", 40);
  MouseControls controls;
  for (int frame = 0; frame < 40; ++frame) {
    controls.update(replay.input(frame, 800, 600, camera, session), false, 800, 600, camera,
                    session);
    session.step();
  }
  REQUIRE(session.grabbed());
  const int node = session.grabbed()->node;
  CHECK(session.scene().mesh.X(0, node) > 0.9);  // the far end of the 1 m beam
  CHECK(session.grabbed()->target.z() > session.scene().mesh.X(2, node));  // pulled up
}

TEST_CASE("a step that overflows resets the session and says why, in every chapter", "[viewer]") {
  // E = 1e306 Pa overflows the system. Whether the NaN reaches the state or stays in the
  // solve's residual (leaving a frozen body), the session must notice, reset and say why.
  SessionSettings settings = test_settings();
  settings.material.youngs_modulus = 1e306;
  for (const ChapterInfo& chapter : chapters()) {
    CAPTURE(chapter.id);
    Session session(test::test_mesh(), settings, chapter.id);
    const Eigen::VectorXd rest = session.state().x;
    CHECK_FALSE(session.step());
    CHECK(session.steps() == 0);
    CHECK(session.state().x == rest);
    CHECK(session.message().find("diverged") != std::string::npos);
    // Eigen's CG (01-05) iterates on with NaN and writes it into the velocities; ours (06,
    // 07) stops at once, and only the residual tells.
    const std::string& message = session.message();
    CHECK((message.find("non-finite positions") != std::string::npos ||
           message.find("residual is not finite") != std::string::npos));
  }
}
