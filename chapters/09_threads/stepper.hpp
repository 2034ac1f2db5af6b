// Chapter 09: every core, deterministically. The same step as before, on all the threads
// OpenMP is given (OMP_NUM_THREADS or --threads): the element pass without races or
// atomics, the block SpMV over rows, the PCG's vector operations fused so that an
// iteration waits at three barriers (parallel_pcg.hpp), and every sum over the mesh taken
// over a FIXED partition in a fixed order, so that the state after any number of steps is
// the same to the last bit for any thread count.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <vector>

#include "chapters/07_block_sparse/block_sparse.hpp"
#include "chapters/08_element_kernels/element_kernels.hpp"
#include "chapters/08_element_kernels/stepper.hpp"
#include "chapters/09_threads/adaptive_team.hpp"
#include "chapters/09_threads/parallel.hpp"
#include "chapters/09_threads/parallel_pcg.hpp"
#include "common/model.hpp"
#include "common/stepper.hpp"

namespace fem::ch09 {

// How the element pass keeps two threads from adding into the same block at once.
enum class ElementParallelism {
  // Each element writes its forces and blocks to its own slots; then the thread that owns
  // a row sums the row's terms, in element order.
  gather,
  // Groups of consecutive elements are coloured so that no two groups of a colour share a
  // node; one colour at a time, the threads scatter as the serial pass does.
  colouring,
};

// Chapter 08's step with three of its phases on every thread: the system's start, the fused
// element pass, and the solve (parallel_pcg.hpp). A derived stepper can change the
// preconditioner alone (use_preconditioner).
class ThreadsStepper : public ch08::ElementKernelsStepper {
 public:
  ThreadsStepper(const Scene& scene, const SolverSettings& settings,
                 ElementParallelism element_parallelism = ElementParallelism::colouring);
  ThreadsStepper(const ThreadsStepper&) = delete;  // preconditioner_ points into *this
  ThreadsStepper& operator=(const ThreadsStepper&) = delete;
  // Chapter 08's step on the team that AdaptiveTeam picks: the program's thread count, or one
  // thread while that is faster (a busy machine). The state is the same either way.
  void step(State& state) override;
  bool uses_threads() const override { return true; }
  int colours() const { return static_cast<int>(colour_start_.size()) - 1; }
  // Tests that compare thread counts keep the count they set (off); the environment variable
  // FEM_ADAPTIVE_TEAM=0 turns it off for a whole program (to see what it prevents).
  AdaptiveTeam& adaptive_team() { return adaptive_team_; }
  const AdaptiveTeam& adaptive_team() const { return adaptive_team_; }

 protected:
  // The PCG's preconditioner from the next step on (block Jacobi until then), and the
  // chapter's name in the solver's warnings. The preconditioner must outlive the stepper.
  void use_preconditioner(Preconditioner& preconditioner, const char* chapter);
  // The parallel PCG on the filtered system from the guess in y_ (virtual: a derived stepper
  // may prepare its preconditioner first).
  void solve() override;
  // The filtered system's solve, y from its guess: chapter 09's parallel PCG with the
  // preconditioner in use (virtual: a derived stepper may solve it its own way).
  virtual SolveStats solve_filtered_system(Eigen::VectorXd& y);
  // Colours groups of `group` consecutive elements (kGroup by default): on a mesh whose
  // elements come sorted along it, long groups are slabs, and fewer colours.
  void colour_element_groups(int group);
  // The colouring's pass, for any way of computing a group's elements (one or several at a
  // time): group(first, last, fallbacks) on the elements [first, last) of every group, colour
  // after colour, on every thread; each thread counts into its own fallbacks, and the sum of
  // all is returned.
  template <class Group>
  long long for_coloured_groups(Group&& group);

 private:
  void start_system(const State& state) override;
  void element_pass(const State& state) override;
  void build_gather_tables();
  void element_pass_gather(const State& state);
  void element_pass_colouring(const State& state);

  ElementParallelism element_parallelism_;
  const char* chapter_ = "09_threads";
  RowChunks chunks_;
  // Gather: each element's terms; per node, its (element, corner) pairs 4 e + a, and per
  // block its (element, block) pairs 16 e + 4 a + b, in element order.
  std::vector<ch08::ElementTerms> element_terms_;
  std::vector<int> node_corner_start_, node_corners_;
  std::vector<int> block_term_start_, block_terms_;
  // Colouring: groups of kGroup consecutive elements, sorted by colour; colour c holds the
  // groups colour_order_[colour_start_[c]] .. colour_order_[colour_start_[c + 1] - 1].
  static constexpr int kGroup = 16;
  int group_ = kGroup;
  std::vector<int> colour_order_, colour_start_;
  ParallelPcg parallel_pcg_;
  AdaptiveTeam adaptive_team_;
  long long steps_taken_ = 0;
  BlockJacobi block_jacobi_;
  Preconditioner* preconditioner_ = &block_jacobi_;
};

template <class Group>
long long ThreadsStepper::for_coloured_groups(Group&& group) {
  long long fallbacks = 0;
  run_parallel([&] {
    long long my_fallbacks = 0;  // this thread's: added to the total once, at the end
    for (int colour = 0; colour < colours(); ++colour) {
      // The barrier at the end of each loop orders the colours: no two threads ever add
      // into the same node's blocks at the same time.
      for (const int k : StaticShare(colour_start_[colour], colour_start_[colour + 1])) {
        const int first = colour_order_[k] * group_;
        group(first, std::min(static_cast<int>(model_.tets.size()), first + group_), my_fallbacks);
      }
    }
    add_count(fallbacks, my_fallbacks);
  });
  return fallbacks;
}

}  // namespace fem::ch09
