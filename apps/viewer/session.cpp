#include "apps/viewer/session.hpp"

#include <algorithm>
#include <stdexcept>

#include "chapters/registry.hpp"
#include "common/model.hpp"

namespace fem::viewer {

namespace {

constexpr std::size_t kHistory = 60;  // steps kept for the panel's averages and plot

Scene build_scene(const SessionSettings& settings, TetMesh mesh) {
  Scene scene = make_scene(settings.scene, std::move(mesh), settings.material);
  scene.dt = settings.dt;
  scene.damping = settings.damping;
  validate(scene);
  return scene;
}

}  // namespace

double spring_stiffness(double body_weight_per_diagonal, double relative_stiffness,
                        double patch_mass, double dt) {
  const double wanted = relative_stiffness * body_weight_per_diagonal;
  const double stable = patch_mass / (dt * dt);
  return std::min(wanted, stable);
}

Session::Session(TetMesh mesh, const SessionSettings& settings, const std::string& chapter)
    : settings_(settings),
      body_(build_scene(settings, std::move(mesh)), settings.solver, find_chapter(chapter).id),
      chapter_(body_.chapter()) {
  if (settings.threads > 0) body_.set_threads(settings.threads);
  measure_body();
}

femcourse::Body Session::make_body(const Scene& scene, const SolverSettings& solver) const {
  femcourse::Body body(scene, solver, chapter_);
  if (settings_.threads > 0) body.set_threads(settings_.threads);  // the asked count steps
  return body;
}

void Session::measure_body() {
  const Scene& scene = body_.scene();
  const Model model(scene);
  node_mass_.resize(model.num_nodes);
  for (int i = 0; i < model.num_nodes; ++i) node_mass_[i] = model.lumped_mass[3 * i];
  const Eigen::Vector3d lo = scene.mesh.X.rowwise().minCoeff();
  const Eigen::Vector3d hi = scene.mesh.X.rowwise().maxCoeff();
  diagonal_ = (hi - lo).norm();
  weight_per_diagonal_ = node_mass_.sum() * scene.gravity.norm() / diagonal_;
}

void Session::set_chapter(const std::string& chapter) {
  body_.set_chapter(chapter);  // the state carries over
  chapter_ = body_.chapter();
  history_.clear();
}

void Session::apply(const SessionSettings& settings) {
  const bool restart = settings.scene != settings_.scene;
  // Throws before anything changes.
  femcourse::Body next = make_body(build_scene(settings, body_.scene().mesh), settings.solver);
  next.set_state(body_.state());
  settings_ = settings;
  body_ = std::move(next);
  measure_body();
  history_.clear();
  if (restart) reset();
}

void Session::reset() {
  body_ = make_body(body_.scene(), settings_.solver);  // forgets the warm start
  time_ = 0.0;
  steps_ = 0;
  fewest_threads_ = most_threads_ = 0;
  grab_.reset();
  history_.clear();
}

bool Session::step() {
  // The scene's own interaction forces, plus the spring: both are the sparse f_ext.
  forces_.clear();
  for (const ExternalForce& f : body_.scene().external_forces)
    forces_.push_back({f.node, {f.force.x(), f.force.y(), f.force.z()}});
  for (const ExternalForce& f : spring_forces())
    forces_.push_back({f.node, {f.force.x(), f.force.y(), f.force.z()}});
  body_.set_forces(forces_);
  try {
    body_.step();
  } catch (const femcourse::StepDiverged& e) {
    message_ = "the simulation diverged at t = " + std::to_string(time_) + " s (" + e.reason +
               ") and was reset: try a smaller dt, a softer spring or more damping";
    reset();
    return false;
  }
  time_ += body_.scene().dt;
  ++steps_;
  const int team = body_.threads_used();
  fewest_threads_ = fewest_threads_ == 0 ? team : std::min(fewest_threads_, team);
  most_threads_ = std::max(most_threads_, team);
  history_.push_back(body_.stepper().profile());
  if (history_.size() > kHistory) history_.pop_front();
  return true;
}

void Session::grab(int node, const Eigen::Vector3d& target) {
  const Scene& scene = body_.scene();
  if (node < 0 || node >= scene.mesh.num_nodes())
    throw std::invalid_argument("grab: node " + std::to_string(node) + " is not in the mesh");
  if (!target.allFinite()) throw std::invalid_argument("grab: the target is not finite");
  grab_ = Grab{node, target};
  patch_.clear();
  patch_mass_ = 0.0;
  const Eigen::Vector3d centre = scene.mesh.X.col(node);
  for (int j = 0; j < scene.mesh.num_nodes(); ++j) {
    if ((scene.mesh.X.col(j) - centre).norm() > kGrabRadius * diagonal_) continue;
    patch_.push_back(j);  // the grabbed node itself is always in
    patch_mass_ += node_mass_[j];
  }
}

void Session::move_grab(const Eigen::Vector3d& target) {
  if (grab_ && target.allFinite()) grab_->target = target;
}

void Session::release() { grab_.reset(); }

std::vector<ExternalForce> Session::spring_forces() const {
  if (!grab_) return {};
  const Scene& scene = body_.scene();
  const State& state = body_.state();
  const double k = spring_stiffness(weight_per_diagonal_, settings_.spring, patch_mass_, scene.dt);
  const Eigen::Vector3d stretch =
      grab_->target - state.x.segment<3>(3 * static_cast<Eigen::Index>(grab_->node));
  const double length = stretch.stableNorm();  // norm() would square 1e300 into infinity
  const double longest = kMaxPull * diagonal_;
  const Eigen::Vector3d pull = k * (length > longest ? (longest / length) * stretch : stretch);
  std::vector<ExternalForce> forces;
  forces.reserve(patch_.size());
  for (const int j : patch_) forces.push_back({j, pull * (node_mass_[j] / patch_mass_)});
  return forces;
}

StepProfile Session::mean_profile() const {
  StepProfile mean;
  if (history_.empty()) return mean;
  const double n = static_cast<double>(history_.size());
  double iterations = 0.0;
  for (const StepProfile& p : history_) {
    for (const StepProfile::Phase& phase : StepProfile::phases())
      (mean.*phase.cost).seconds += (p.*phase.cost).seconds / n;
    iterations += p.cg_iterations / n;
    mean.converged = mean.converged && p.converged;
  }
  mean.cg_iterations = static_cast<int>(iterations + 0.5);
  mean.relative_residual = history_.back().relative_residual;
  return mean;
}

}  // namespace fem::viewer
