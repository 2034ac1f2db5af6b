// Chapter 14's element part: chapter 12's batches, with the next batch's lines of memory asked
// for while this batch's lanes compute. Once the lanes are busy, what holds the element pass on
// a large body is the scatter: each element adds sixteen 3x3 blocks into A at slots spread over
// four block rows, and on the ~82k-node beam A is 83 MB, more than the last cache, so each
// block's lines come from memory and the core waits on them (`fem_lessons batched-elements`:
// the scatter 46 ns an element on the plate, 113 on the beam, one thread). The slots are known
// at set-up (the index's element blocks, chapter 07), so the wait can overlap the next batch's
// arithmetic: a software prefetch (GCC's and Clang's __builtin_prefetch) of the next batch's
// sixteen blocks (two lines each) and its corners' x, v and b, issued before this batch's terms.
// Where A fits in the last cache the prefetches are only instructions (they cost the plate's
// pass 5-10%), so they are issued only where it does not: chosen once, at set-up, from A's size
// against the last cache the machine reports, as the finest level's layout is.
#pragma once

#include <ostream>

#include "chapters/08_element_kernels/step.hpp"
#include "chapters/09_threads/threaded_elements.hpp"
#include "chapters/12_half_the_bytes/element_batch.hpp"
#include "common/caches.hpp"

namespace fem::ch14 {

class PrefetchedElementPass {
 public:
  struct Params {
    // The cache A is weighed against (by default the last the machine reports; 0 where it does
    // not say: A taken as in memory, the batches fetched ahead).
    long long cache_bytes = last_cache_bytes();
  };
  static constexpr const char* kName =
      "element pass in batches of one element per lane, the next batch fetched ahead";
  static constexpr std::string_view kChapter = FEM_PART_CHAPTER;

  PrefetchedElementPass(const ch08::PartSetup& setup, const Params& params);
  void start_system(const ch08::StepInput& in, const State& state, ch08::System& system) const {
    colouring_.start_system(in, state, system);
  }
  // Chapter 12's pass (its batches, their terms and scatter in the same order: the same A and
  // b to the bit), with the prefetches where A does not fit in the cache.
  void pass(const ch08::StepInput& in, const State& state, ch08::System& system);

  bool fetches_ahead() const { return ahead_; }
  const ch12::BatchedElements& batched_elements() const { return batched_; }
  int colours() const { return colouring_.colours(); }
  void describe(std::ostream& out) const;

 private:
  ch09::ElementColouring colouring_;
  ch12::BatchedElements batched_;
  double a_bytes_ = 0.0;  // A's blocks
  long long cache_bytes_ = 0;
  bool ahead_ = false;
};

}  // namespace fem::ch14
