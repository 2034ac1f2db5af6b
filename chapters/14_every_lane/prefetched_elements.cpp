#include "chapters/14_every_lane/prefetched_elements.hpp"

#include <algorithm>
#include <iomanip>

namespace fem::ch14 {

namespace {

// Asks for the lines elements [first, last) will read and write: their blocks of A (72 bytes,
// two lines where a block straddles one), and x, v and b at their corners. Write intent for
// what the scatter adds into. Always inlined: as a function of its own, GCC 12 took it for one
// without effects (a prefetch changes no value) and dropped its calls, prefetches and all (the
// object held no prefetch instruction, and the beam's pass ran as fast as chapter 12's).
EIGEN_ALWAYS_INLINE void fetch_ahead(int first, int last, const std::vector<Eigen::Vector4i>& tets,
                                     const std::vector<std::array<int, 16>>& element_blocks,
                                     const State& state, const ch08::System& system) {
  for (int e = first; e < last; ++e) {
    for (const int k : element_blocks[e]) {
      const double* block = system.A.blocks[k].data();
      __builtin_prefetch(block, 1);
      __builtin_prefetch(block + 8, 1);
    }
    for (int a = 0; a < 4; ++a) {
      const int node = 3 * tets[e][a];
      __builtin_prefetch(state.x.data() + node);
      __builtin_prefetch(state.v.data() + node);
      __builtin_prefetch(system.b.data() + node, 1);
    }
  }
}

}  // namespace

PrefetchedElementPass::PrefetchedElementPass(const ch08::PartSetup& setup, const Params& params)
    : colouring_(setup, setup.element_group),
      batched_(setup.model, setup.scene),
      a_bytes_(double(sizeof(Eigen::Matrix3d)) * double(setup.system.A.blocks.size())),
      cache_bytes_(params.cache_bytes),
      ahead_(a_bytes_ > double(params.cache_bytes)) {}

void PrefetchedElementPass::pass(const ch08::StepInput& in, const State& state,
                                 ch08::System& system) {
  using ch12::kLanes;
  const auto& tets = in.model.tets;
  const auto& element_blocks = system.index.element;
  batched_.end_pass(colouring_.for_coloured_groups([&](int first, int last, long long& fallbacks) {
    ch12::BatchTerms terms;  // on this thread's stack: no allocation, no sharing
    for (int e = first; e < last; e += kLanes) {
      const int count = std::min(kLanes, last - e);
      // The next batch of this group: its lines arrive while this batch's lanes compute.
      if (ahead_)
        fetch_ahead(e + count, std::min(last, e + count + kLanes), tets, element_blocks, state,
                    system);
      batched_.terms(e, count, tets, state, fallbacks, terms);
      for (int l = 0; l < count; ++l)
        ch12::scatter(terms, l, tets[e + l], element_blocks[e + l], system.A, system.b);
    }
  }));
}

void PrefetchedElementPass::describe(std::ostream& out) const {
  const double mib = 1 << 20;
  out << "    chapter 12's batches; A " << std::fixed << std::setprecision(1) << a_bytes_ / mib
      << " MiB against a last cache of " << double(cache_bytes_) / mib
      << " MiB: " << (ahead_ ? "the next batch fetched ahead" : "no fetching ahead") << "\n"
      << std::defaultfloat;
}

}  // namespace fem::ch14
