// The viewer's simulation, without any graphics: a scene, the stepper of the chosen
// chapter, the state, the mouse spring, and the recent step profiles. Switching
// chapters keeps the state, so the motion goes on and only the cost changes.
#pragma once

#include <Eigen/Core>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "common/scene.hpp"
#include "common/stepper.hpp"
#include "femcourse/simulator.hpp"

namespace fem::viewer {

// What the panel can change. A change of scene or mesh restarts from rest; a change of
// material, damping or dt keeps the state (a new stepper continues from it).
struct SessionSettings {
  std::string scene = "cantilever";
  Material material;
  RayleighDamping damping;
  double dt = 0.01;
  SolverSettings solver;
  double spring = 10.0;  // the mouse spring's relative stiffness, see spring_stiffness()
  int threads = 0;       // asked for (--threads): every step runs on it; 0: the library's choice
};

// The mouse spring: pulls a surface node towards a target point. The force acts on the
// nodes within a small rest distance of it (kGrabRadius of the bounding-box diagonal), in
// proportion to their mass, so that a single node is not torn out of the mesh and the
// stable stiffness (below) is that of a patch, not of one node.
struct Grab {
  int node = -1;
  Eigen::Vector3d target = Eigen::Vector3d::Zero();
};

// Spring stiffness [N/m] as a multiple of the body's weight per bounding-box diagonal:
// at 1, pulling the node by a tenth of the diagonal takes a tenth of the body's weight.
// The force is explicit (it is not in the linearized system), so the stiffness is
// capped where an explicit spring on the patch's mass would become unstable:
// k h^2 <= m_patch (symplectic Euler on a spring is stable below k h^2 / m = 4).
double spring_stiffness(double body_weight_per_diagonal, double relative_stiffness,
                        double patch_mass, double dt);
constexpr double kGrabRadius = 0.05;
// The spring's length is capped at this many bounding-box diagonals: a mouse ray that
// grazes the drag plane puts the target very far away, and must not fling the body.
constexpr double kMaxPull = 2.0;

class Session {
 public:
  Session(TetMesh mesh, const SessionSettings& settings, const std::string& chapter);

  // Replaces the chapter's stepper; the state carries over.
  void set_chapter(const std::string& chapter);
  // Applies new settings: restarts from rest when the scene changes.
  void apply(const SessionSettings& settings);
  void reset();  // back to rest, t = 0

  // One step of dt with the current spring. Returns false, and restarts from rest, when
  // the step produced non-finite values (the message says what to change).
  bool step();

  // Throws std::invalid_argument for a node not in the mesh or a non-finite target.
  void grab(int node, const Eigen::Vector3d& target);
  void move_grab(const Eigen::Vector3d& target);  // a non-finite target is ignored
  void release();
  const std::optional<Grab>& grabbed() const { return grab_; }

  const Scene& scene() const { return body_.scene(); }
  const State& state() const { return body_.state(); }
  const SessionSettings& settings() const { return settings_; }
  const std::string& chapter() const { return chapter_; }
  const StepProfile& last_profile() const { return body_.stepper().profile(); }
  bool uses_threads() const { return body_.stepper().uses_threads(); }
  // The threads the steps since the start (or the last reset) ran on, as the stepper's team
  // recorded them: {fewest, most}; {0, 0} before the first step.
  std::pair<int, int> threads_ran() const { return {fewest_threads_, most_threads_}; }
  // The profiles of the last steps (oldest first), for averages and plots.
  const std::deque<StepProfile>& history() const { return history_; }
  StepProfile mean_profile() const;
  double time() const { return time_; }
  long long steps() const { return steps_; }
  const std::string& message() const { return message_; }  // the last warning, if any

  // The spring's forces on the patch of the grabbed node (empty when nothing is grabbed).
  std::vector<ExternalForce> spring_forces() const;

 private:
  void measure_body();
  femcourse::Body make_body(const Scene& scene, const SolverSettings& solver) const;

  SessionSettings settings_;
  femcourse::Body body_;  // the scene, the chapter's stepper and the state (the library's API)
  std::string chapter_;
  Eigen::VectorXd node_mass_;         // lumped mass per node
  double diagonal_ = 0.0;             // of the rest bounding box [m]
  double weight_per_diagonal_ = 0.0;  // [N/m]
  std::vector<int> patch_;            // the grabbed node's neighbours within kGrabRadius
  double patch_mass_ = 0.0;
  std::optional<Grab> grab_;
  std::vector<femcourse::NodeForce> forces_;  // the scene's and the spring's, passed to the body
  std::deque<StepProfile> history_;
  double time_ = 0.0;
  long long steps_ = 0;
  int fewest_threads_ = 0, most_threads_ = 0;
  std::string message_;
};

}  // namespace fem::viewer
