// Chapter 09's element part: the system's start and the fused element pass on every thread,
// without races or atomics, the same bits for any thread count. Two ways are kept (the lesson
// measures both): each element to its own slots, then each row summed by the thread that owns
// it (gather), or groups of elements coloured so that no two groups of a colour share a node,
// one colour at a time (colouring, the default).
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <vector>

#include "chapters/08_element_kernels/element_kernels.hpp"
#include "chapters/08_element_kernels/step.hpp"
#include "chapters/09_threads/parallel.hpp"
#include "chapters/09_threads/parallel_pcg.hpp"

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

// The colouring of groups of consecutive elements, and the system's start row by row on the
// fixed chunks: what any threaded element pass needs (chapter 12's batched pass too).
class ElementColouring {
 public:
  static constexpr int kGroup = 16;  // elements per group, unless the order asks for others

  // Colours groups of `group` consecutive elements (kGroup if 0): on a mesh whose elements
  // come sorted along it, long groups are slabs, and fewer colours.
  ElementColouring(const ch08::PartSetup& setup, int group);
  int colours() const { return static_cast<int>(colour_start_.size()) - 1; }
  int group() const { return group_; }
  const RowChunks& chunks() const { return chunks_; }

  // A = (1 + h alpha) M, b = h (f_gravity - alpha M v + f_ext), row by row on the thread that
  // owns the row.
  void start_system(const ch08::StepInput& in, const State& state, ch08::System& system) const;
  // The colouring's pass, for any way of computing a group's elements (one or several at a
  // time): group(first, last, fallbacks) on the elements [first, last) of every group, colour
  // after colour, on every thread; each thread counts into its own fallbacks, and the sum of
  // all is returned.
  template <class Group>
  long long for_coloured_groups(Group&& group) const;

 private:
  RowChunks chunks_;
  int elements_ = 0;
  int group_ = kGroup;
  // Groups sorted by colour; colour c holds the groups colour_order_[colour_start_[c]] ..
  // colour_order_[colour_start_[c + 1] - 1].
  std::vector<int> colour_order_, colour_start_;
};

// Elements: chapter 08's fused pass on every thread (colouring or gather).
class ThreadedElements {
 public:
  struct Params {
    ElementParallelism parallelism = ElementParallelism::colouring;
  };
  static constexpr const char* kName = "fused element pass, coloured groups on every thread";
  static constexpr std::string_view kChapter = FEM_PART_CHAPTER;

  ThreadedElements(const ch08::PartSetup& setup, const Params& params);
  void start_system(const ch08::StepInput& in, const State& state, ch08::System& system) const {
    colouring_.start_system(in, state, system);
  }
  void pass(const ch08::StepInput& in, const State& state, ch08::System& system);

  const ch08::FusedElements& fused() const { return elements_; }
  const ElementColouring& colouring() const { return colouring_; }
  ElementParallelism parallelism() const { return parallelism_; }
  int colours() const { return colouring_.colours(); }

 private:
  void build_gather_tables(const ch08::PartSetup& setup);
  void pass_gather(const ch08::StepInput& in, const State& state, ch08::System& system);
  void pass_colouring(const ch08::StepInput& in, const State& state, ch08::System& system);

  ElementParallelism parallelism_;
  ch08::FusedElements elements_;
  ElementColouring colouring_;
  // Gather: each element's terms; per node, its (element, corner) pairs 4 e + a, and per
  // block its (element, block) pairs 16 e + 4 a + b, in element order.
  std::vector<ch08::ElementTerms> element_terms_;
  std::vector<int> node_corner_start_, node_corners_;
  std::vector<int> block_term_start_, block_terms_;
};

template <class Group>
long long ElementColouring::for_coloured_groups(Group&& group) const {
  long long fallbacks = 0;
  run_parallel([&] {
    long long my_fallbacks = 0;  // this thread's: added to the total once, at the end
    for (int colour = 0; colour < colours(); ++colour) {
      // The barrier at the end of each loop orders the colours: no two threads ever add
      // into the same node's blocks at the same time.
      for (const int k : StaticShare(colour_start_[colour], colour_start_[colour + 1])) {
        const int first = colour_order_[k] * group_;
        group(first, std::min(elements_, first + group_), my_fallbacks);
      }
    }
    add_count(fallbacks, my_fallbacks);
  });
  return fallbacks;
}

}  // namespace fem::ch09
