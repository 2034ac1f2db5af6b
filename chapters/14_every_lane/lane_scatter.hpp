// Chapter 14's element part: chapter 12's batches of one element per lane, their scatter into
// A at the vector width, and the next batch's lines of memory asked for while this batch's
// lanes compute. Chapter 12 computes a batch's terms in full registers, then scatters them
// lane by lane and entry by entry: each element adds sixteen 3x3 blocks into A, each entry a
// strided load from the batch's registers, a load, an addition and a store, and that takes
// longer than the terms (chapter 12's `fem_lessons batched-elements` table). On AVX-512 a
// block's first eight entries fit one register: each pair's lanes are transposed once a batch,
// and a block is added by one load, one addition and one store (lane_scatter.cpp). And where A
// is larger than the last cache the machine reports, each block's lines come from memory
// and the scatter waits on them, the longer the larger the mesh (the same table): the slots
// are known at set-up (the index's element blocks, chapter 07), so the next batch's sixteen
// blocks and its corners' x, v and b are prefetched (__builtin_prefetch, GCC and Clang) before
// this batch's terms. Where A fits, the prefetches would only be instructions (on the plate
// they slowed the pass): chosen once at set-up from A's size against the last cache the
// machine reports, as the finest level's layout is.
#pragma once

#include <ostream>

#include "chapters/08_element_kernels/step.hpp"
#include "chapters/09_threads/threaded_elements.hpp"
#include "chapters/12_half_the_bytes/element_batch.hpp"
#include "common/caches.hpp"

namespace fem::ch14 {

class LaneScatterPass {
 public:
  struct Params {
    // The cache A is weighed against (by default the last the machine reports; 0 where it does
    // not say: A taken as in memory, the batches fetched ahead).
    long long cache_bytes = last_cache_bytes();
  };
  static constexpr const char* kName =
      "element pass in batches of one element per lane, scattered a register a block";
  static constexpr std::string_view kChapter = FEM_PART_CHAPTER;

  LaneScatterPass(const ch08::PartSetup& setup, const Params& params);
  void start_system(const ch08::StepInput& in, const State& state, ch08::System& system) const {
    colouring_.start_system(in, state, system);
  }
  // Chapter 12's pass (its batches, their terms, the same additions into A and b in the same
  // order: the same bits), scattered a register a block, fetched ahead where A does not fit.
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
