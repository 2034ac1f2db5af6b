// Two recipes with one mistake each, compiled by wrong_recipe.sh one at a time (-DMISTAKE=1 or
// 2): each must fail with exactly one error, check_recipe's sentence naming the role and what
// it lacks.
#include "chapters/09_threads/stepper.hpp"

namespace {

using namespace fem;

#if MISTAKE == 1
// A recipe without its Guess.
struct NoGuess {
  using Order = ch08::MeshOrder;
  using Team = ch09::TeamOfThreads;
  using Elements = ch09::ThreadedElements;
  using Product = ch08::AssembledProduct;
  using Preconditioner = ch09::JacobiOnChunks;
  using Solver = ch09::ParallelPcgSolver;
};
using Wrong = NoGuess;
#else
// A preconditioner that is not a ch08::PreconditionerPart (it has no prepare, no apply).
struct NotAPreconditioner {
  struct Params {};
  static constexpr const char* kName = "nothing";
  static constexpr std::string_view kChapter = "none";
  NotAPreconditioner(const ch08::PartSetup&, const Params&) {}
};
struct WrongPreconditioner : ch09::Threads {
  using Preconditioner = NotAPreconditioner;
};
using Wrong = WrongPreconditioner;
#endif

}  // namespace

int main() {
  const Scene scene;
  ch08::StepOf<Wrong> stepper(scene, SolverSettings{});
  State state;
  stepper.step(state);
}
