// Chapter 08's building block: the step, written once, over a recipe of named parts.
//
// One linearized backward Euler step (Baraff & Witkin 1998),
//   A dv = b,  A = M - h df/dv - h^2 df/dx,  b = h (f + h df/dx v),
// with velocity constraints by the filter S of the PPCG method (Tamstorf et al. 2015):
//   (S A S^T + I - S) y = S (b - A z),  dv = y + z.
// From chapter 08 on the course changes the step's parts, never its order: the nodes'
// numbering, the team of threads, the element pass (with the start of the system it writes
// into), the solve's guess, its preconditioner and its solver. A chapter names its parts in a
// recipe (its stepper.hpp), as Eigen's ConjugateGradient<Matrix, UpLo, Preconditioner> and
// AMGCL's make_solver<amg<...>, solver::cg<...>> take theirs as types:
//
//   struct Recipe {
//     using Order = ...;           // the numbering the step runs in (in and out of the caller's)
//     using Team = ...;            // the threads a step runs on
//     using Elements = ...;        // compose: A and b's start; forces: the fused element pass
//     using Guess = ...;           // the solve's first guess from the last solutions
//     using Preconditioner = ...;  // M, set up per solve and applied per iteration
//     using Solver = ...;          // the Krylov iteration that stops at the tolerance
//   };
//
// Each part owns its data and is built from the scene in the step's numbering (PartSetup)
// and its own Params. A part names itself (kName) and the chapter that teaches it (kChapter,
// from the folder of the file that declares it), so that the phase table and the printed
// summary of a stepper come from the recipe, not from reading the code.
#pragma once

#include <Eigen/Core>
#include <ostream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include "chapters/07_block_sparse/block_sparse.hpp"
#include "common/model.hpp"
#include "common/stepper.hpp"

namespace fem::ch08 {

using ch07::BlockIndex;
using ch07::BlockSparseMatrix;

// The chapter folder ("09_threads") of a source path (__FILE__ of a part's header): the
// chapter that teaches the part. A student's variant, a copy of the folder, names itself.
constexpr std::string_view chapter_of_file(std::string_view file) {
  const std::size_t at = file.rfind("chapters/");
  if (at == std::string_view::npos) return "common";
  const std::string_view rest = file.substr(at + 9);
  return rest.substr(0, rest.find('/'));
}
#define FEM_PART_CHAPTER ::fem::ch08::chapter_of_file(__FILE__)

// The system a step builds and solves, written by the parts in the step's order.
struct System {
  BlockSparseMatrix A;         // M - h df/dv - h^2 df/dx, the mesh's block pattern
  BlockIndex index;            // where element, diagonal and transposed blocks sit in A
  Eigen::VectorXd b;           // h (f + h df/dx v)
  Eigen::VectorXd z;           // prescribed velocity change of constrained dofs
  Eigen::VectorXd filtered_b;  // S (b - A z)
  Eigen::VectorXd y;           // the filtered system's unknown, dv = y + z: the warm start
  Eigen::VectorXd dv;

  System(const Scene& scene, const Model& model);
};

// What every part is built from: the scene and model in the step's numbering, the system's
// pattern, the solver's settings, and the element groups the order asks for (0: the pass's
// own choice).
struct PartSetup {
  const Scene& scene;
  const Model& model;
  const System& system;
  const SolverSettings& settings;
  int element_group = 0;
};

// What the element parts read during a step besides the state.
struct StepInput {
  const Scene& scene;
  const Model& model;
  const Eigen::SparseVector<double>& f_ext;
};

// A part as the summaries list it: its role in the recipe, its name and its chapter.
struct PartName {
  const char* role;
  const char* name;
  std::string_view chapter;
};

// Every part's Params in one aggregate: `StepParams<R> p; p.preconditioner = ...;`.
template <class Recipe>
struct StepParams {
  typename Recipe::Order::Params order{};
  typename Recipe::Elements::Params elements{};
  typename Recipe::Guess::Params guess{};
  typename Recipe::Preconditioner::Params preconditioner{};
};

// A part with more to say than its name (the multigrid's levels) has describe(std::ostream&).
template <class Part, class = void>
struct HasDescribe : std::false_type {};
template <class Part>
struct HasDescribe<Part, std::void_t<decltype(std::declval<const Part&>().describe(
                             std::declval<std::ostream&>()))>> : std::true_type {};

// The parts' own descriptions, for the parts that have one.
template <class... Parts>
void describe_parts(std::ostream& out, const Parts&... parts) {
  const auto one = [&out](const auto& part) {
    if constexpr (HasDescribe<std::decay_t<decltype(part)>>::value) part.describe(out);
  };
  (one(parts), ...);
}

template <class Recipe>
class StepOf final : public Stepper {
 public:
  using Order = typename Recipe::Order;
  using Team = typename Recipe::Team;
  using Elements = typename Recipe::Elements;
  using Guess = typename Recipe::Guess;
  using Preconditioner = typename Recipe::Preconditioner;
  using Solver = typename Recipe::Solver;
  using Params = StepParams<Recipe>;

  StepOf(const Scene& scene, const SolverSettings& settings, const Params& params = {})
      : Stepper(scene),
        settings_(settings),
        order_(scene, params.order),
        model_(order_.scene()),
        system_(order_.scene(), model_),
        elements_(setup(), params.elements),
        guess_(setup(), params.guess),
        preconditioner_(setup(), params.preconditioner),
        solver_(setup(), preconditioner_) {
    set_external_forces(scene.external_forces);  // in the step's numbering
  }
  StepOf(const StepOf&) = delete;  // the parts hold references into each other and *this
  StepOf& operator=(const StepOf&) = delete;

  void step(State& state) override {
    order_.step(state, [this](State& inner) {
      team_.run([&] { step_in_order(inner); }, profile_.step.seconds);
    });
  }
  const StepProfile& profile() const override { return profile_; }
  bool uses_threads() const override { return Team::kThreads; }
  void set_external_forces(const std::vector<ExternalForce>& forces) override {
    Stepper::set_external_forces(order_.inward(forces));
    order_.outward(f_ext_);
  }
  const Eigen::SparseVector<double>& external_forces() const override {
    return order_.outward_forces(f_ext_);
  }
  // The recipe, one line a part, and what the parts built (AMGCL prints its hierarchy the same
  // way): `out << stepper`.
  void describe(std::ostream& out) const override {
    out << "nodes " << model_.num_nodes << ", tetrahedra " << model_.tets.size() << ", blocks of A "
        << system_.A.blocks.size() << "\n";
    for_each_part([&out](const PartName& part) {
      out << "  " << part.role << ": " << part.name << " (" << part.chapter << ")\n";
    });
    describe_parts(out, order_, elements_, preconditioner_);
  }

  // Constraints change while the body runs (a grab, a release, a floor's contacts): the order
  // renames them, the step's filter and the solver read them from the next step on. The
  // preconditioner keeps what it was set up with (a multigrid's rigid-body modes): under the
  // PCG's filter it stays a symmetric positive definite preconditioner, perhaps a weaker one.
  // Throws std::invalid_argument for a node out of range, and changes nothing then.
  bool can_change_constraints() const override { return true; }
  void set_constraints(const std::vector<NodeConstraint>& constraints) override {
    for (const NodeConstraint& c : constraints)
      if (c.node < 0 || c.node >= model_.num_nodes)
        throw std::invalid_argument("set_constraints: no node " + std::to_string(c.node));
    order_.set_constraints(constraints);
    solver_.set_constraints(order_.scene().constraints);
  }

  // The parts, for the tests, the lessons, the roofline and the summary.
  const Scene& scene() const { return order_.scene(); }  // in the step's numbering
  const Model& model() const { return model_; }
  const SolverSettings& settings() const { return settings_; }
  const System& system() const { return system_; }
  const Order& order() const { return order_; }
  Team& team() { return team_; }
  const Team& team() const { return team_; }
  const Elements& elements() const { return elements_; }
  const Guess& guess() const { return guess_; }
  Preconditioner& preconditioner() { return preconditioner_; }
  const Preconditioner& preconditioner() const { return preconditioner_; }
  Solver& solver() { return solver_; }
  const Solver& solver() const { return solver_; }
  // The last step's filtered system S A S^T + I - S and right-hand side S (b - A z).
  const BlockSparseMatrix& system_matrix() const { return system_.A; }
  const Eigen::VectorXd& system_rhs() const { return system_.filtered_b; }

  // Which part runs each of the step's phases (the phase-owners table of chapters/README.md,
  // printed by `fem_lessons phase-owners`): the whole step runs in the order's numbering on the
  // team, the constraints are the step's own (chapter 07's filter in place), the solve is the
  // guess, the preconditioner and the solver.
  static std::vector<std::pair<const char*, PartName>> phase_owners() {
    const PartName elements{"elements", Elements::kName, Elements::kChapter};
    const PartName step{"step", "the step, with the constraint filter in place", FEM_PART_CHAPTER};
    return {{"step", {"order", Order::kName, Order::kChapter}},
            {"step", {"team", Team::kName, Team::kChapter}},
            {"forces", elements},
            {"compose", elements},
            {"constraints", step},
            {"solve", {"guess", Guess::kName, Guess::kChapter}},
            {"solve", {"preconditioner", Preconditioner::kName, Preconditioner::kChapter}},
            {"solve", {"solver", Solver::kName, Solver::kChapter}}};
  }

  // f(PartName) for each part, in the recipe's order.
  template <class F>
  static void for_each_part(F&& f) {
    f(PartName{"order", Order::kName, Order::kChapter});
    f(PartName{"team", Team::kName, Team::kChapter});
    f(PartName{"elements", Elements::kName, Elements::kChapter});
    f(PartName{"guess", Guess::kName, Guess::kChapter});
    f(PartName{"preconditioner", Preconditioner::kName, Preconditioner::kChapter});
    f(PartName{"solver", Solver::kName, Solver::kChapter});
  }

 private:
  PartSetup setup() const {
    return {order_.scene(), model_, system_, settings_, order_.element_group()};
  }

  void step_in_order(State& state) {
    PhaseTimer total(profile_.step);
    const StepInput input{order_.scene(), model_, f_ext_};
    {
      // What the elements do not touch: A = (1 + h alpha) M, b = h (f_g - alpha M v + f_ext).
      PhaseTimer t(profile_.compose);
      elements_.start_system(input, state, system_);
    }
    {
      // The fused pass: rotations, forces and the blocks of df/dx, written into A and b. It
      // does the work of the earlier chapters' forces, df/dx and composition phases and is
      // reported under forces; dfdx stays zero, because no df/dx is built.
      PhaseTimer t(profile_.forces);
      elements_.pass(input, state, system_);
    }
    profile_.dfdx = PhaseCost{};
    {
      PhaseTimer t(profile_.constraints);
      ch07::apply_constraints(order_.scene().constraints, state.v, system_.index, system_.b,
                              system_.A, system_.z, system_.filtered_b);
    }
    {
      PhaseTimer t(profile_.solve);
      guess_.guess(system_.y);  // y still holds the last step's answer
      const SolveStats result = solver_.solve(system_, preconditioner_, settings_);
      system_.dv = system_.y;
      system_.dv += system_.z;
      profile_.record(result);
      report_if_not_converged(profile_, settings_, name().c_str(), warned_not_converged_);
    }
    state.v += system_.dv;
    state.x += order_.scene().dt * state.v;
  }

  SolverSettings settings_;
  StepProfile profile_;
  bool warned_not_converged_ = false;
  // The parts, in the order they are built: each part's set-up may read those before it.
  Order order_;
  Model model_;
  System system_;
  Team team_;
  Elements elements_;
  Guess guess_;
  Preconditioner preconditioner_;
  Solver solver_;
};

}  // namespace fem::ch08
