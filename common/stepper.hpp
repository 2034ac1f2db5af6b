// The interface every chapter implements, and what it measures about each step.
#pragma once

#include <Eigen/SparseCore>
#include <array>
#include <chrono>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include "common/allocation_hook.hpp"
#include "common/scene.hpp"
#include "common/sync_hook.hpp"

namespace fem {

// What one phase of a step cost: time, heap allocations when the allocation counter is
// linked into the program (tests, benchmarks; zero otherwise), and the synchronizations its
// threads met (chapter 09 on; zero before): parallel regions opened, barriers met, a team's
// counted once. The roofline prices the last two at their measured costs (the phase's waiting).
struct PhaseCost {
  double seconds = 0.0;
  long long allocations = 0;
  long long regions = 0, barriers = 0;
};

// What a preconditioned CG reports about one solve (chapters 06 on).
struct SolveStats {
  int iterations = 0;
  // ||r|| / ||b|| with r the recurrence residual (r -= step q), filtered, which is what
  // Eigen's ConjugateGradient::error() reports too: it equals ||S (b - A y)|| / ||b|| only up
  // to the rounding the recurrence accumulates.
  double relative_residual = 0.0;
  bool converged = false;
};

// The poster's phases during the last step, plus solver facts.
struct StepProfile {
  PhaseCost forces;       // rotations and element forces (identical in every chapter)
  PhaseCost dfdx;         // df/dx construction: clean the matrix, scatter -R K0 R^T
  PhaseCost compose;      // system composition: A = M - h df/dv - h^2 df/dx, and b
  PhaseCost constraints;  // the filter: S A S + I - S and S (b - A z)
  PhaseCost solve;        // the linear solve
  PhaseCost step;         // the whole step, all of the above and the update
  int cg_iterations = 0;
  double relative_residual = 0.0;  // ||r|| / ||rhs|| of the last solve
  bool converged = true;           // false when the solve stopped at the iteration cap

  void record(const SolveStats& solve) {
    cg_iterations = solve.iterations;
    relative_residual = solve.relative_residual;
    converged = solve.converged;
  }

  // The phases above, in the poster's order, each with its name in the results
  // (bench.json's "phases", its per-phase tables): the one list the bench, the roofline and
  // the viewer iterate, so a phase added here reaches all of them. The last, "step", is the
  // whole step.
  struct Phase {
    const char* name;
    PhaseCost StepProfile::*cost;
  };
  static constexpr std::size_t kPhaseCount = 6;
  static const std::array<Phase, kPhaseCount>& phases();
  // f(name, cost) for each phase in order, on this profile's costs.
  template <class F>
  void for_each_phase(F&& f) const {
    for (const Phase& p : phases()) f(p.name, this->*p.cost);
  }
};

inline const std::array<StepProfile::Phase, StepProfile::kPhaseCount>& StepProfile::phases() {
  static constexpr std::array<Phase, kPhaseCount> table = {{
      {"forces", &StepProfile::forces},
      {"dfdx", &StepProfile::dfdx},
      {"compose", &StepProfile::compose},
      {"constraints", &StepProfile::constraints},
      {"solve", &StepProfile::solve},
      {"step", &StepProfile::step},
  }};
  return table;
}

// Conjugate gradient settings, the same for every chapter so that timings compare.
// Eigen's default tolerance is machine epsilon: always set it explicitly.
struct SolverSettings {
  double tolerance = 1e-4;  // relative residual ||r|| <= tolerance * ||rhs||
  int max_iterations = 2000;
};

class Stepper {
 public:
  virtual ~Stepper() = default;
  // Advances the state by one linearized backward Euler step of scene.dt.
  virtual void step(State& state) = 0;
  virtual const StepProfile& profile() const = 0;
  // True for the chapters whose step runs on OpenMP's thread count (09 on); the others run
  // on one thread whatever it is: the registry steps them inside a OneThreadScope
  // (common/threads.hpp, on_one_thread below), and the benchmark measures the first kind at
  // each count. A variant that threads a chapter of its own (chapter 07's exercise 3)
  // overrides it to return true.
  virtual bool uses_threads() const { return false; }
  // The threads the last step ran on, by the stepper's own record (0: it does not say).
  virtual int threads_used() const { return 0; }

  // Replaces the sparse interaction forces from the next step on: the scene's own, or
  // the viewer's mouse spring. The storage is reused, so once it has held as many
  // nonzeros this allocates nothing. Throws std::invalid_argument for a node out of
  // range or a non-finite force. (Virtual so that on_one_thread's wrapper can pass them on,
  // and a stepper that numbers the nodes its own way can rename them.)
  virtual void set_external_forces(const std::vector<ExternalForce>& forces);
  virtual const Eigen::SparseVector<double>& external_forces() const { return f_ext_; }

  // What the stepper built, for a reader: its parts and what they hold (a stepper made of
  // parts, chapter 08 on, prints its recipe and its multigrid's levels); `out << stepper`.
  virtual void describe(std::ostream& out) const;

  // The chapter's id the registry made this stepper for ("" when made directly): the
  // stepper's warnings name it. (Virtual so that on_one_thread's wrapper can pass it on.)
  virtual void set_name(const std::string& name) { name_ = name; }
  const std::string& name() const { return name_; }

  // Replaces the scene's constraints from the next step on (a grab, a release, a floor's
  // contacts: femcourse::Body). Only a stepper that says can_change_constraints() does so; the
  // others were built around their constraints (the filter's pattern, the preconditioner) and
  // throw std::logic_error, and the library rebuilds them from the scene instead.
  virtual bool can_change_constraints() const { return false; }
  virtual void set_constraints(const std::vector<NodeConstraint>& constraints);

 protected:
  explicit Stepper(const Scene& scene);

  // The poster's `sparse_vec`: a few nonzeros among 3N, kept sparse so that adding it to
  // a dense vector touches only those entries.
  Eigen::SparseVector<double> f_ext_;

 private:
  std::string name_;
};

inline std::ostream& operator<<(std::ostream& out, const Stepper& stepper) {
  stepper.describe(out);
  return out;
}

// The stepper itself when it uses_threads(); otherwise a stepper that runs each of its steps
// inside a OneThreadScope (OpenMP's and Eigen's thread counts at 1, restored after), so that
// a single-threaded chapter runs on one thread in every program whatever --threads or
// OMP_NUM_THREADS say. The registry's make_stepper and ChapterInfo::make return this.
std::unique_ptr<Stepper> on_one_thread(std::unique_ptr<Stepper> stepper, const Scene& scene);
// The chapter's own stepper inside on_one_thread's wrapper (itself when not wrapped): the
// roofline lesson reads the data structures it holds.
const Stepper& unwrapped(const Stepper& stepper);
Stepper& unwrapped(Stepper& stepper);

// Measures one phase into a StepProfile field: `PhaseTimer t(profile_.solve);`. Made and
// ended outside the parallel regions (on the thread that steps), so the synchronizations
// between are the phase's. Two relaxed loads per hook at each end: nothing beside a phase.
class PhaseTimer {
 public:
  explicit PhaseTimer(PhaseCost& cost)
      : cost_(cost),
        allocations_(count_allocations()),
        syncs_(count_syncs()),
        start_(Clock::now()) {}
  ~PhaseTimer() {
    cost_.seconds = std::chrono::duration<double>(Clock::now() - start_).count();
    cost_.allocations = count_allocations() - allocations_;
    const Synchronizations now = count_syncs();
    cost_.regions = now.regions - syncs_.regions;
    cost_.barriers = now.barriers - syncs_.barriers;
  }
  PhaseTimer(const PhaseTimer&) = delete;
  PhaseTimer& operator=(const PhaseTimer&) = delete;

 private:
  using Clock = std::chrono::steady_clock;
  static long long count_allocations() {
    return allocation_count_hook ? allocation_count_hook() : 0;
  }
  static Synchronizations count_syncs() {
    return sync_count_hook ? sync_count_hook() : Synchronizations{};
  }
  PhaseCost& cost_;
  long long allocations_;
  Synchronizations syncs_;
  Clock::time_point start_;
};

}  // namespace fem

namespace fem {

// Where the steppers' warnings go: std::cerr, unless the thread that steps has a sink in
// scope (the library hands them to its caller: femcourse::Body's warning handler). Per
// thread, so that two bodies stepped from two threads keep their own.
class WarningSinkScope {
 public:
  using Sink = void (*)(void* context, const std::string& message);
  WarningSinkScope(Sink sink, void* context);
  ~WarningSinkScope();
  WarningSinkScope(const WarningSinkScope&) = delete;
  WarningSinkScope& operator=(const WarningSinkScope&) = delete;

 private:
  Sink previous_sink_;
  void* previous_context_;
};
// Sends one warning (a line, without "warning: " and newline) to the sink in scope.
void warn(const std::string& message);

// Warns once the first time a stepper's solve stops at the iteration cap, so that
// non-convergence is never silent and never floods the output.
void report_if_not_converged(const StepProfile& profile, const SolverSettings& settings,
                             const char* chapter, bool& already_warned);

// Why the last step cannot be trusted, or nullptr when it can: non-finite positions or
// velocities, a solve whose residual is not finite, or a solve stopped at the iteration cap
// with a relative residual above 1 (worse than dv = 0). The second happens when the system
// overflows (an absurd E or dt): CG then stops at once and leaves the state finite but
// frozen, which a check of the positions alone would let pass silently. The third happens
// with a near-incompressible material (nu = 0.4999999): every step ran to the cap, finite.
const char* divergence(const State& state, const StepProfile& profile);

}  // namespace fem
