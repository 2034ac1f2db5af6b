// Chapter 08's building block: what each part of a recipe must provide, written once and
// checked by the compiler. StepOf (step.hpp) builds the parts in this order and calls them:
//
// | role           | constructed from               | members StepOf or the solver calls        |
// | -------------- | ------------------------------ | ----------------------------------------- |
// | Order          | (const Scene&, const Params&)  | scene(), element_group(), step(state, f), |
// |                |                                | set_constraints(c), inward(forces),       |
// |                |                                | outward(f_ext), outward_forces(f_ext)     |
// | Team           | default                        | run(f, step_seconds), kThreads, threads() |
// | Elements       | (const PartSetup&, const Params&) | start_system(in, state, system) const, |
// |                |                                | pass(in, state, system)                   |
// | Guess          | (const PartSetup&, const Params&) | guess(y)                               |
// | Product        | (const PartSetup&, const Params&) | a ProductPart: prepare(A),             |
// |                |                                | multiply_rows(x, y, first, last)          |
// | Preconditioner | (const PartSetup&, const Params&) | a PreconditionerPart: prepare(A),      |
// |                |                                | apply(r, s) [, block_diagonal(),          |
// |                |                                | apply_rows(first, last, r, s),            |
// |                |                                | set_constraints(c)]                       |
// | Solver         | (const PartSetup&, const Params&) | solve(system, product, preconditioner, |
// |                |                                | settings), set_constraints(c)             |
//
// Every part also names itself and the chapter that teaches it (kName, kChapter), and every part
// but the Team has a Params struct (an empty one where it takes none). A part with more to say
// than its name has describe(std::ostream&), printed by `out << stepper`.
//
// The solver meets the product and the preconditioner only through the two faces below, as
// Eigen's ConjugateGradient calls precond.solve(r) and AMGCL's solvers call P.apply(rhs, x) on
// whatever preconditioner they are given: so any solver runs with any preconditioner and any
// product. A part may offer more (chapter 13's fused cycle); a solver that can use it asks at
// compile time and falls back to the face where a part does not offer it.
//
// check_recipe<Recipe>() turns each missing role or member into one static_assert sentence
// naming both (as chapter 10's check_level_kernels does for a level's kernels), instead of an
// error at the call deep inside the step.
#pragma once

#include <Eigen/Core>
#include <array>
#include <ostream>
#include <string_view>
#include <tuple>
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

// The product face: q = A p for the solver, on the filtered system matrix of this step. A part
// may keep A in another layout (chapter 14's pair lanes), which prepare() fills.
// Both members are called by every thread of the solver's team (one thread in chapter 08's
// solver, every thread inside chapter 09's parallel region); a part that shares out work in
// prepare() ends with a barrier, so that every row is ready before the first product.
class ProductPart {
 public:
  virtual ~ProductPart() = default;
  // This solve's A (assembled and filtered), before the first product.
  virtual void prepare(const BlockSparseMatrix& A) = 0;
  // y = A x on block rows [first, last): it reads x on the rows' neighbours.
  virtual void multiply_rows(const Eigen::VectorXd& x, Eigen::VectorXd& y, int first,
                             int last) const = 0;
};

// The preconditioner face: s = M r for the solver. Both members are called by every thread of
// the solver's team, which the part shares its work out to (a V-cycle over its levels' row
// blocks); each ends with a barrier, so that the solver may read s on any row after it.
class PreconditionerPart {
 public:
  virtual ~PreconditionerPart() = default;
  // This solve's numbers from A, before the first apply.
  virtual void prepare(const BlockSparseMatrix& A) = 0;
  // s = M r on every row.
  virtual void apply(const Eigen::VectorXd& r, Eigen::VectorXd& s) = 0;
  // A block-diagonal M reads only the rows it writes: a solver may apply it chunk by chunk
  // inside its own loops, with no barrier (apply_rows, which such a part must override).
  virtual bool block_diagonal() const { return false; }
  virtual void apply_rows(int first, int last, const Eigen::VectorXd& r, Eigen::VectorXd& s) const;
  // The constraints changed while the body runs (in the step's numbering), from the next
  // prepare on. A part built only from each step's A needs nothing; one that keeps what it set
  // up from the constraints (a multigrid's coarse space) sets it up again.
  virtual void set_constraints(const std::vector<NodeConstraint>& constraints);
};

// The roles, in the order StepOf builds them: the one list that the phase owners, the walk over
// the parts and the printed summary iterate.
inline constexpr std::array<const char*, 7> kRoles = {
    "order", "team", "elements", "guess", "product", "preconditioner", "solver"};

// The recipe's parts as types, in kRoles' order.
template <class Recipe>
using RecipeParts =
    std::tuple<typename Recipe::Order, typename Recipe::Team, typename Recipe::Elements,
               typename Recipe::Guess, typename Recipe::Product, typename Recipe::Preconditioner,
               typename Recipe::Solver>;

// A part as the summaries list it: its role in the recipe, its name and its chapter.
struct PartName {
  const char* role;
  const char* name;
  std::string_view chapter;
};

// ---- the checks ------------------------------------------------------------------------------

namespace recipe_checks {

#define FEM_DETECT(NAME, EXPRESSION) \
  template <class T, class = void>   \
  struct NAME : std::false_type {};  \
  template <class T>                 \
  struct NAME<T, std::void_t<decltype(EXPRESSION)>> : std::true_type {}

template <class T>
T& ref();  // only in unevaluated expressions

// The roles.
FEM_DETECT(has_order, std::declval<typename T::Order>);
FEM_DETECT(has_team, std::declval<typename T::Team>);
FEM_DETECT(has_elements, std::declval<typename T::Elements>);
FEM_DETECT(has_guess, std::declval<typename T::Guess>);
FEM_DETECT(has_product, std::declval<typename T::Product>);
FEM_DETECT(has_preconditioner, std::declval<typename T::Preconditioner>);
FEM_DETECT(has_solver, std::declval<typename T::Solver>);

// What every part has.
FEM_DETECT(has_name, std::string_view(T::kName));
FEM_DETECT(has_chapter, std::string_view(T::kChapter));
FEM_DETECT(has_params, std::declval<typename T::Params>);
FEM_DETECT(built_from_setup, T(ref<const PartSetup>(), ref<const typename T::Params>()));

// Order.
struct Inner {
  void operator()(State&) const {}
};
FEM_DETECT(built_from_scene, T(ref<const Scene>(), ref<const typename T::Params>()));
FEM_DETECT(has_scene, static_cast<const Scene&>(ref<const T>().scene()));
FEM_DETECT(has_element_group, int(ref<const T>().element_group()));
FEM_DETECT(has_order_step, ref<T>().step(ref<State>(), Inner{}));
FEM_DETECT(has_set_constraints, ref<T>().set_constraints(ref<const std::vector<NodeConstraint>>()));
FEM_DETECT(has_inward, static_cast<const std::vector<ExternalForce>&>(
                           ref<T>().inward(ref<const std::vector<ExternalForce>>())));
FEM_DETECT(has_outward, ref<T>().outward(ref<const Eigen::SparseVector<double>>()));
FEM_DETECT(has_outward_forces,
           static_cast<const Eigen::SparseVector<double>&>(
               ref<const T>().outward_forces(ref<const Eigen::SparseVector<double>>())));

// Team.
struct Body {
  void operator()() const {}
};
FEM_DETECT(has_run, ref<T>().run(Body{}, ref<const double>()));
FEM_DETECT(has_threads_flag, bool(T::kThreads));
FEM_DETECT(has_threads_used, int(ref<const T>().threads()));

// Elements.
FEM_DETECT(has_start_system,
           ref<const T>().start_system(ref<const StepInput>(), ref<const State>(), ref<System>()));
FEM_DETECT(has_pass, ref<T>().pass(ref<const StepInput>(), ref<const State>(), ref<System>()));

// Guess.
FEM_DETECT(has_guess_member, ref<T>().guess(ref<Eigen::VectorXd>()));

#undef FEM_DETECT

// Solver, with the recipe's product and preconditioner.
template <class Solver, class Product, class Preconditioner, class = void>
struct has_solve : std::false_type {};
template <class Solver, class Product, class Preconditioner>
struct has_solve<
    Solver, Product, Preconditioner,
    std::void_t<decltype(SolveStats(ref<Solver>().solve(
        ref<System>(), ref<Product>(), ref<Preconditioner>(), ref<const SolverSettings>())))>>
    : std::true_type {};

}  // namespace recipe_checks

// Whether every role of `Recipe` is there.
template <class Recipe>
constexpr bool recipe_has_roles() {
  using namespace recipe_checks;
  return has_order<Recipe>::value && has_team<Recipe>::value && has_elements<Recipe>::value &&
         has_guess<Recipe>::value && has_product<Recipe>::value &&
         has_preconditioner<Recipe>::value && has_solver<Recipe>::value;
}

namespace recipe_checks {

template <class Part>
constexpr bool named() {
  return has_name<Part>::value && has_chapter<Part>::value;
}
template <class Part>
constexpr bool built() {
  if constexpr (has_params<Part>::value)
    return built_from_setup<Part>::value;
  else
    return false;
}

// Each check once, for a recipe with every role: check_recipe asserts them one by one, each
// with its sentence; StepOf builds the step only where all hold.
template <class Recipe>
struct Members {
  using Order = typename Recipe::Order;
  using Team = typename Recipe::Team;
  using Elements = typename Recipe::Elements;
  using Guess = typename Recipe::Guess;
  using Product = typename Recipe::Product;
  using Preconditioner = typename Recipe::Preconditioner;
  using Solver = typename Recipe::Solver;
  static constexpr bool names[7] = {named<Order>(), named<Team>(),    named<Elements>(),
                                    named<Guess>(), named<Product>(), named<Preconditioner>(),
                                    named<Solver>()};
  static constexpr bool order_built = built_from_scene<Order>::value;
  static constexpr bool order_scene = has_scene<Order>::value;
  static constexpr bool order_group = has_element_group<Order>::value;
  static constexpr bool order_step = has_order_step<Order>::value;
  static constexpr bool order_constraints = has_set_constraints<Order>::value;
  static constexpr bool order_forces =
      has_inward<Order>::value && has_outward<Order>::value && has_outward_forces<Order>::value;
  static constexpr bool team_built = std::is_default_constructible_v<Team>;
  static constexpr bool team_run = has_run<Team>::value;
  static constexpr bool team_threads =
      has_threads_flag<Team>::value && has_threads_used<Team>::value;
  static constexpr bool elements_built = built<Elements>();
  static constexpr bool elements_start = has_start_system<Elements>::value;
  static constexpr bool elements_pass = has_pass<Elements>::value;
  static constexpr bool guess_built = built<Guess>();
  static constexpr bool guess_guess = has_guess_member<Guess>::value;
  static constexpr bool product_built = built<Product>();
  static constexpr bool product_face = std::is_base_of_v<ProductPart, Product>;
  static constexpr bool preconditioner_built = built<Preconditioner>();
  static constexpr bool preconditioner_face = std::is_base_of_v<PreconditionerPart, Preconditioner>;
  static constexpr bool solver_built = built<Solver>();
  static constexpr bool solver_solve = has_solve<Solver, Product, Preconditioner>::value;
  static constexpr bool solver_constraints = has_set_constraints<Solver>::value;

  static constexpr bool all() {
    for (const bool n : names)
      if (!n) return false;
    return order_built && order_scene && order_group && order_step && order_constraints &&
           order_forces && team_built && team_run && team_threads && elements_built &&
           elements_start && elements_pass && guess_built && guess_guess && product_built &&
           product_face && preconditioner_built && preconditioner_face && solver_built &&
           solver_solve && solver_constraints;
  }
};

}  // namespace recipe_checks

// Whether `Recipe` names every role and every part brings every member its role needs: StepOf
// builds its step only then, and otherwise reports check_recipe's sentences and nothing else.
template <class Recipe>
constexpr bool recipe_is_whole() {
  if constexpr (recipe_has_roles<Recipe>())
    return recipe_checks::Members<Recipe>::all();
  else
    return false;
}

// Each missing role of `Recipe` as one static_assert sentence naming it.
template <class Recipe>
constexpr bool check_roles() {
  using namespace recipe_checks;
  static_assert(has_order<Recipe>::value, "Recipe: no Order (using Order = ...;)");
  static_assert(has_team<Recipe>::value, "Recipe: no Team (using Team = ...;)");
  static_assert(has_elements<Recipe>::value, "Recipe: no Elements (using Elements = ...;)");
  static_assert(has_guess<Recipe>::value, "Recipe: no Guess (using Guess = ...;)");
  static_assert(has_product<Recipe>::value, "Recipe: no Product (using Product = ...;)");
  static_assert(has_preconditioner<Recipe>::value,
                "Recipe: no Preconditioner (using Preconditioner = ...;)");
  static_assert(has_solver<Recipe>::value, "Recipe: no Solver (using Solver = ...;)");
  return true;
}

// Each missing role or member of `Recipe` as one static_assert sentence naming both.
template <class Recipe>
constexpr bool check_recipe() {
  using namespace recipe_checks;
  static_assert(check_roles<Recipe>());
  if constexpr (recipe_has_roles<Recipe>()) {
    using M = Members<Recipe>;
    static_assert(M::names[0], "Order part: no kName or kChapter");
    static_assert(M::names[1], "Team part: no kName or kChapter");
    static_assert(M::names[2], "Elements part: no kName or kChapter");
    static_assert(M::names[3], "Guess part: no kName or kChapter");
    static_assert(M::names[4], "Product part: no kName or kChapter");
    static_assert(M::names[5], "Preconditioner part: no kName or kChapter");
    static_assert(M::names[6], "Solver part: no kName or kChapter");
    static_assert(M::order_built,
                  "Order part: no Params, or no constructor (const Scene&, const Params&)");
    static_assert(M::order_scene, "Order part: no scene() returning const Scene&");
    static_assert(M::order_group, "Order part: no element_group()");
    static_assert(M::order_step, "Order part: no step(State&, inner)");
    static_assert(M::order_constraints,
                  "Order part: no set_constraints(const std::vector<NodeConstraint>&)");
    static_assert(M::order_forces,
                  "Order part: no inward(forces), outward(f_ext) or outward_forces(f_ext)");
    static_assert(M::team_built, "Team part: not default-constructible");
    static_assert(M::team_run, "Team part: no run(step, const double& step_seconds)");
    static_assert(M::team_threads, "Team part: no kThreads, or no threads() of the last step");
    static_assert(M::elements_built,
                  "Elements part: no Params, or no constructor (const PartSetup&, const Params&)");
    static_assert(M::elements_start,
                  "Elements part: no start_system(const StepInput&, const State&, System&) const");
    static_assert(M::elements_pass,
                  "Elements part: no pass(const StepInput&, const State&, System&)");
    static_assert(M::guess_built,
                  "Guess part: no Params, or no constructor (const PartSetup&, const Params&)");
    static_assert(M::guess_guess, "Guess part: no guess(Eigen::VectorXd& y)");
    static_assert(M::product_built,
                  "Product part: no Params, or no constructor (const PartSetup&, const Params&)");
    static_assert(M::product_face,
                  "Product part: not a ch08::ProductPart (prepare(A), multiply_rows(x, y, first, "
                  "last))");
    static_assert(
        M::preconditioner_built,
        "Preconditioner part: no Params, or no constructor (const PartSetup&, const Params&)");
    static_assert(M::preconditioner_face,
                  "Preconditioner part: not a ch08::PreconditionerPart (prepare(A), apply(r, s))");
    static_assert(M::solver_built,
                  "Solver part: no Params, or no constructor (const PartSetup&, const Params&)");
    // (Checked where the product and the preconditioner are parts: else it follows from theirs.)
    static_assert(!M::product_face || !M::preconditioner_face || M::solver_solve,
                  "Solver part: no solve(System&, Product&, Preconditioner&, const "
                  "SolverSettings&) returning SolveStats for the recipe's product and "
                  "preconditioner");
    static_assert(M::solver_constraints,
                  "Solver part: no set_constraints(const std::vector<NodeConstraint>&)");
  }
  return true;
}

}  // namespace fem::ch08
