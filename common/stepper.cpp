#include "common/stepper.hpp"

#include <cmath>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>

#include "common/threads.hpp"

namespace fem {

long long (*allocation_count_hook)() = nullptr;
Synchronizations (*sync_count_hook)() = nullptr;

Stepper::Stepper(const Scene& scene) : f_ext_(3 * scene.mesh.num_nodes()) {
  set_external_forces(scene.external_forces);
}

void Stepper::set_external_forces(const std::vector<ExternalForce>& forces) {
  const Eigen::Index num_nodes = f_ext_.size() / 3;
  for (const ExternalForce& e : forces) {
    if (e.node < 0 || e.node >= num_nodes)
      throw std::invalid_argument("external force on node " + std::to_string(e.node) +
                                  ", which is not in [0, " + std::to_string(num_nodes) + ")");
    if (!e.force.allFinite())
      throw std::invalid_argument("external force on node " + std::to_string(e.node) +
                                  " is not finite");
  }
  // setZero() empties the sparse vector but keeps its capacity; coeffRef inserts in
  // order and sums the forces that act on the same node.
  f_ext_.setZero();
  for (const ExternalForce& e : forces)
    for (int r = 0; r < 3; ++r) f_ext_.coeffRef(3 * e.node + r) += e.force[r];
}

void Stepper::set_constraints(const std::vector<NodeConstraint>& /*constraints*/) {
  throw std::logic_error("this chapter's stepper cannot change its constraints while it runs");
}

namespace {

// A single-threaded chapter's stepper, stepped on one thread. Everything else is passed on.
class OneThreadStepper final : public Stepper {
 public:
  OneThreadStepper(std::unique_ptr<Stepper> inner, const Scene& scene)
      : Stepper(scene), inner_(std::move(inner)) {}
  void step(State& state) override {
    const OneThreadScope one_thread;
    inner_->step(state);
  }
  const StepProfile& profile() const override { return inner_->profile(); }
  bool uses_threads() const override { return false; }
  int threads_used() const override { return 1; }
  void set_external_forces(const std::vector<ExternalForce>& forces) override {
    inner_->set_external_forces(forces);
  }
  void describe(std::ostream& out) const override { inner_->describe(out); }
  void set_name(const std::string& name) override {
    Stepper::set_name(name);
    inner_->set_name(name);
  }
  const Eigen::SparseVector<double>& external_forces() const override {
    return inner_->external_forces();
  }
  bool can_change_constraints() const override { return inner_->can_change_constraints(); }
  void set_constraints(const std::vector<NodeConstraint>& constraints) override {
    inner_->set_constraints(constraints);
  }
  const Stepper& inner() const { return *inner_; }

 private:
  std::unique_ptr<Stepper> inner_;
};

}  // namespace

std::unique_ptr<Stepper> on_one_thread(std::unique_ptr<Stepper> stepper, const Scene& scene) {
  if (!stepper || stepper->uses_threads()) return stepper;
  return std::make_unique<OneThreadStepper>(std::move(stepper), scene);
}

const Stepper& unwrapped(const Stepper& stepper) {
  const auto* wrapper = dynamic_cast<const OneThreadStepper*>(&stepper);
  return wrapper ? wrapper->inner() : stepper;
}

Stepper& unwrapped(Stepper& stepper) {
  // The wrapper holds the stepper it was given, which is not const: the cast only undoes the
  // const of the const overload's answer.
  return const_cast<Stepper&>(unwrapped(static_cast<const Stepper&>(stepper)));
}

void Stepper::describe(std::ostream& out) const {
  // A chapter before 08 is one class: its step is its only part.
  out << "one stepper class: every phase in its own step()\n";
}

namespace {
thread_local WarningSinkScope::Sink current_sink = nullptr;
thread_local void* current_context = nullptr;
}  // namespace

WarningSinkScope::WarningSinkScope(Sink sink, void* context)
    : previous_sink_(current_sink), previous_context_(current_context) {
  current_sink = sink;
  current_context = context;
}

WarningSinkScope::~WarningSinkScope() {
  current_sink = previous_sink_;
  current_context = previous_context_;
}

void warn(const std::string& message) {
  if (current_sink)
    current_sink(current_context, message);
  else
    std::cerr << "warning: " << message << "\n";
}

void report_if_not_converged(const StepProfile& profile, const SolverSettings& settings,
                             const char* chapter, bool& already_warned) {
  if (profile.converged || already_warned) return;
  already_warned = true;
  std::ostringstream message;
  message << (*chapter ? chapter : "stepper") << ": ";
  if (std::isfinite(profile.relative_residual))
    message << "the linear solve stopped at the iteration cap (" << settings.max_iterations
            << ") with relative residual " << profile.relative_residual << " > tolerance "
            << settings.tolerance;
  else
    message << "the linear solve broke down after " << profile.cg_iterations
            << " iterations (non-finite residual)";
  message << " (reported once; see StepProfile::converged for every step)";
  warn(message.str());
}

const char* divergence(const State& state, const StepProfile& profile) {
  if (!state.x.allFinite() || !state.v.allFinite()) return "non-finite positions or velocities";
  if (!std::isfinite(profile.relative_residual))
    return "the linear solve's residual is not finite: the system overflows";
  // Above 1, ||b - A dv|| > ||b||: the solve's answer is further from solving the system
  // than dv = 0, not a step at all (near-incompressible material, nu -> 0.5, does this to CG
  // at its iteration cap). Below 1 a capped solve is an inexact step: warned and counted.
  if (!profile.converged && profile.relative_residual > 1.0)
    return "the linear solve did not converge: at the iteration cap its relative residual is "
           "above 1, worse than no solve (a near-incompressible nu, or too few iterations allowed)";
  return nullptr;
}

}  // namespace fem
