// Chapter 12's element part (see parts.hpp).
#include "chapters/12_half_the_bytes/parts.hpp"

#include <algorithm>

namespace fem::ch12 {

BatchedElementPass::BatchedElementPass(const ch08::PartSetup& setup, const Params&)
    : colouring_(setup, setup.element_group), batched_(setup.model, setup.scene) {}

void BatchedElementPass::pass(const ch08::StepInput& in, const State& state, ch08::System& system) {
  // Chapter 09's colour loop; inside a group, kLanes consecutive elements at a time, each
  // batch's terms scattered in element order, so the sums (and the state) are the same for
  // any thread count.
  const auto& tets = in.model.tets;
  const auto& element_blocks = system.index.element;
  auto& A = system.A;
  auto& b = system.b;
  batched_.end_pass(colouring_.for_coloured_groups([&](int first, int last, long long& fallbacks) {
    BatchTerms terms;  // on this thread's stack: no allocation, no sharing
    for (int e = first; e < last; e += kLanes) {
      const int count = std::min(kLanes, last - e);
      batched_.terms(e, count, tets, state, fallbacks, terms);
      for (int l = 0; l < count; ++l) scatter(terms, l, tets[e + l], element_blocks[e + l], A, b);
    }
  }));
}

}  // namespace fem::ch12
