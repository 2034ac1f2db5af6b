// Chapter 08's building block: the step, written once, over a recipe of named parts.
//
// One linearized backward Euler step (Baraff & Witkin 1998),
//   A dv = b,  A = M - h df/dv - h^2 df/dx,  b = h (f + h df/dx v),
// with velocity constraints by the filter S of the PPCG method (Tamstorf et al. 2015):
//   (S A S^T + I - S) y = S (b - A z),  dv = y + z.
// From chapter 08 on the course changes the step's parts, never its order: the nodes'
// numbering, the team of threads, the element pass (with the start of the system it writes
// into), the solve's guess, its product q = A p, its preconditioner and its solver. A chapter
// names its parts in a recipe (its stepper.hpp), as Eigen's ConjugateGradient<Matrix, UpLo,
// Preconditioner> and AMGCL's make_solver<amg<...>, solver::cg<...>> take theirs as types:
//
//   struct Recipe {
//     using BuildsOn = ...;        // the recipe this one changes (from chapter 09 on)
//     using Order = ...;           // the numbering the step runs in (in and out of the caller's)
//     using Team = ...;            // the threads a step runs on
//     using Elements = ...;        // compose: A and b's start; forces: the fused element pass
//     using Guess = ...;           // the solve's first guess from the last solutions
//     using Product = ...;         // q = A p, as the solver runs it
//     using Preconditioner = ...;  // M, set up per solve and applied per iteration
//     using Solver = ...;          // the Krylov iteration that stops at the tolerance
//   };
//
// What each part must provide is contract.hpp's table, checked by check_recipe<Recipe>(): a
// recipe that lacks a role or a member fails to compile with one sentence naming both. Each
// part owns its data and is built from the scene in the step's numbering (PartSetup) and its
// own Params. A part names itself (kName) and the chapter that teaches it (kChapter, from the
// folder of the file that declares it), so that the phase table and the printed summary of a
// stepper come from the recipe, not from reading the code.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <ostream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include "chapters/07_block_sparse/block_sparse.hpp"
#include "chapters/08_element_kernels/contract.hpp"
#include "common/model.hpp"
#include "common/stepper.hpp"

namespace fem::ch08 {

// Every part's Params in one aggregate: `StepParams<R> p; p.preconditioner = ...;`.
template <class Recipe>
struct StepParams {
  typename Recipe::Order::Params order{};
  typename Recipe::Elements::Params elements{};
  typename Recipe::Guess::Params guess{};
  typename Recipe::Product::Params product{};
  typename Recipe::Preconditioner::Params preconditioner{};
  typename Recipe::Solver::Params solver{};
};

// A part with more to say than its name (the multigrid's levels) has describe(std::ostream&).
template <class Part, class = void>
struct HasDescribe : std::false_type {};
template <class Part>
struct HasDescribe<Part, std::void_t<decltype(std::declval<const Part&>().describe(
                             std::declval<std::ostream&>()))>> : std::true_type {};

// The step of a whole recipe (below), or, for a recipe that is not whole, a stand-in whose only
// content is check_recipe's sentences: the compiler reports what the recipe lacks and nothing
// that follows from it.
template <class Recipe, bool = recipe_is_whole<Recipe>()>
class StepOf final : public Stepper {
  static_assert(check_recipe<Recipe>());

 public:
  template <class... Arguments>
  explicit StepOf(Arguments&&...) : Stepper(Scene{}) {}
  void step(State&) override {}
  const StepProfile& profile() const override { return profile_; }

 private:
  StepProfile profile_;
};

template <class Recipe>
class StepOf<Recipe, true> final : public Stepper {
 public:
  using Order = typename Recipe::Order;
  using Team = typename Recipe::Team;
  using Elements = typename Recipe::Elements;
  using Guess = typename Recipe::Guess;
  using Product = typename Recipe::Product;
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
        product_(setup(), params.product),
        preconditioner_(setup(), params.preconditioner),
        solver_(setup(), params.solver) {
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
  int threads_used() const override { return team_.threads(); }
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
    std::apply([&out](const auto&... part) { (describe_part(out, part), ...); }, parts());
  }

  // Constraints change while the body runs (a grab, a release, a floor's contacts): the order
  // renames them, the step's filter, the preconditioner and the solver read them from the next
  // step on (a multigrid sets its coarse space up again: PreconditionerPart::set_constraints).
  // Throws std::invalid_argument for a node out of range, and changes nothing then.
  bool can_change_constraints() const override { return true; }
  void set_constraints(const std::vector<NodeConstraint>& constraints) override {
    for (const NodeConstraint& c : constraints)
      if (c.node < 0 || c.node >= model_.num_nodes)
        throw std::invalid_argument("set_constraints: no node " + std::to_string(c.node));
    order_.set_constraints(constraints);
    preconditioner_.set_constraints(order_.scene().constraints);
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
  Product& product() { return product_; }
  const Product& product() const { return product_; }
  Preconditioner& preconditioner() { return preconditioner_; }
  const Preconditioner& preconditioner() const { return preconditioner_; }
  Solver& solver() { return solver_; }
  const Solver& solver() const { return solver_; }
  // The last step's filtered system S A S^T + I - S and right-hand side S (b - A z).
  const BlockSparseMatrix& system_matrix() const { return system_.A; }
  const Eigen::VectorXd& system_rhs() const { return system_.filtered_b; }

  // f(PartName) for each part, in the recipe's order (contract.hpp's kRoles).
  template <class F>
  static void for_each_part(F&& f) {
    for_each_part(f, std::make_index_sequence<kRoles.size()>{});
  }
  // The part that plays `role` (one of kRoles).
  static PartName part(std::string_view role) {
    PartName found{"", "", ""};
    for_each_part([&](const PartName& p) {
      if (role == p.role) found = p;
    });
    return found;
  }

  // Which part runs each of the step's phases (the phase-owners table of chapters/README.md,
  // printed by `fem_lessons phase-owners`): the whole step runs in the order's numbering on the
  // team, the constraints are the step's own (chapter 07's filter in place), the solve is the
  // guess, the product, the preconditioner and the solver.
  static std::vector<std::pair<const char*, PartName>> phase_owners() {
    static constexpr std::pair<const char*, const char*> kPhaseRoles[] = {
        {"step", "order"},       {"step", "team"},
        {"forces", "elements"},  {"compose", "elements"},
        {"constraints", "step"}, {"solve", "guess"},
        {"solve", "product"},    {"solve", "preconditioner"},
        {"solve", "solver"}};
    const PartName step{"step", "the step, with the constraint filter in place", FEM_PART_CHAPTER};
    std::vector<std::pair<const char*, PartName>> owners;
    for (const auto& [phase, role] : kPhaseRoles)
      owners.push_back({phase, std::string_view(role) == "step" ? step : part(role)});
    return owners;
  }

 private:
  template <class F, std::size_t... I>
  static void for_each_part(F& f, std::index_sequence<I...>) {
    (f(PartName{kRoles[I], std::tuple_element_t<I, RecipeParts<Recipe>>::kName,
                std::tuple_element_t<I, RecipeParts<Recipe>>::kChapter}),
     ...);
  }
  // The parts themselves, in kRoles' order.
  auto parts() const {
    return std::tie(order_, team_, elements_, guess_, product_, preconditioner_, solver_);
  }
  template <class Part>
  static void describe_part(std::ostream& out, const Part& part) {
    if constexpr (HasDescribe<Part>::value) part.describe(out);
  }

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
      const SolveStats result = solver_.solve(system_, product_, preconditioner_, settings_);
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
  Product product_;
  Preconditioner preconditioner_;
  Solver solver_;
};

}  // namespace fem::ch08
