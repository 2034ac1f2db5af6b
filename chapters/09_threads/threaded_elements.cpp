// Chapter 09's element part (see threaded_elements.hpp). Three rules keep it correct and the
// result independent of the thread count:
//  - a thread writes only what it owns: the rows of its chunks, or its elements' slots;
//  - every parallel loop over rows goes over the same fixed chunks (RowChunks);
//  - a sum over the mesh is a sum of per-chunk sums added in chunk order, never an
//    OpenMP reduction (whose order of combination OpenMP leaves unspecified).
#include "chapters/09_threads/threaded_elements.hpp"

#include <algorithm>
#include <array>
#include <numeric>

namespace fem::ch09 {

namespace {

// list[start[r] ..] = the terms t with target(t) = r, in increasing t: a table read the other
// way round (a CSR transpose), so that each sum adds in the serial pass's order.
template <class Target>
void invert(int rows, int terms, const Target& target, std::vector<int>& start,
            std::vector<int>& list) {
  start.assign(rows + 1, 0);
  for (int t = 0; t < terms; ++t) ++start[target(t) + 1];
  std::partial_sum(start.begin(), start.end(), start.begin());
  list.resize(terms);
  std::vector<int> next(start.begin(), start.end() - 1);
  for (int t = 0; t < terms; ++t) list[next[target(t)]++] = t;
}

// Greedy colouring of groups of `group` consecutive elements: each group takes the first
// colour that no group sharing one of its nodes has. Returns the colour of each group.
std::vector<int> colour_groups(const std::vector<Eigen::Vector4i>& tets, int nodes, int group) {
  const int num_elements = static_cast<int>(tets.size());
  const int groups = (num_elements + group - 1) / group;
  std::vector<std::vector<int>> node_colours(nodes);
  std::vector<int> colour(groups);
  for (int g = 0; g < groups; ++g) {
    const int first = g * group, last = std::min(num_elements, first + group);
    const auto taken = [&](int candidate) {
      for (int e = first; e < last; ++e)
        for (int a = 0; a < 4; ++a) {
          const auto& used = node_colours[tets[e][a]];
          if (std::find(used.begin(), used.end(), candidate) != used.end()) return true;
        }
      return false;
    };
    int c = 0;
    while (taken(c)) ++c;
    colour[g] = c;
    for (int e = first; e < last; ++e)
      for (int a = 0; a < 4; ++a) node_colours[tets[e][a]].push_back(c);
  }
  return colour;
}

// Element block (a, b), 4 a + b, is pair p of kUpperPairs, transposed when a > b.
struct PairOf {
  int pair;
  bool transposed;
};
std::array<PairOf, 16> pair_of_blocks() {
  std::array<PairOf, 16> table{};
  for (int p = 0; p < static_cast<int>(ch08::kUpperPairs.size()); ++p) {
    const int a = ch08::kUpperPairs[p][0], b = ch08::kUpperPairs[p][1];
    table[4 * a + b] = {p, false};
    if (a != b) table[4 * b + a] = {p, true};
  }
  return table;
}
const std::array<PairOf, 16> kPairOf = pair_of_blocks();

}  // namespace

ElementColouring::ElementColouring(const ch08::PartSetup& setup, int group)
    : chunks_(setup.system.A), elements_(static_cast<int>(setup.model.tets.size())) {
  // Groups of consecutive elements rather than single elements: a group keeps the mesh
  // order's locality (its elements share nodes, hence cache lines).
  group_ = group > 0 ? group : kGroup;
  const std::vector<int> colour = colour_groups(setup.model.tets, setup.model.num_nodes, group_);
  const int colours = colour.empty() ? 0 : 1 + *std::max_element(colour.begin(), colour.end());
  invert(
      colours, static_cast<int>(colour.size()), [&colour](int g) { return colour[g]; },
      colour_start_, colour_order_);
}

void ElementColouring::start_system(const ch08::StepInput& in, const State& state,
                                    ch08::System& system) const {
  const double h = in.scene.dt, alpha = in.scene.damping.alpha;
  const double mass_factor = 1.0 + h * alpha;
  auto& A = system.A;
  auto& b = system.b;
  const auto& diagonal = system.index.diagonal;
  const Model& model = in.model;
  run_parallel([&] {
    for (const int c : StaticShare(chunks_.count())) {
      for (int k = A.row_start[chunks_.start[c]]; k < A.row_start[chunks_.start[c + 1]]; ++k)
        A.blocks[k].setZero();
      for (int i = chunks_.start[c]; i < chunks_.start[c + 1]; ++i)
        A.blocks[diagonal[i]].diagonal() = mass_factor * model.lumped_mass.segment<3>(3 * i);
      const int first = chunks_.first_dof(c), size = chunks_.dofs(c);
      b.segment(first, size).noalias() =
          h * model.gravity_force.segment(first, size) -
          (h * alpha) *
              model.lumped_mass.segment(first, size).cwiseProduct(state.v.segment(first, size));
    }
  });
  b += h * in.f_ext;  // a few nonzeros, added into a dense vector: not worth a thread
}

ThreadedElements::ThreadedElements(const ch08::PartSetup& setup, const Params& params)
    : parallelism_(params.parallelism),
      elements_(setup.model, setup.scene),
      colouring_(setup, setup.element_group) {
  if (parallelism_ == ElementParallelism::gather) build_gather_tables(setup);
}

void ThreadedElements::build_gather_tables(const ch08::PartSetup& setup) {
  // The element-to-block table read the other way round, by node and by block. Filled in
  // element order, so that each sum adds in the serial pass's order.
  const auto& tets = setup.model.tets;
  const auto& element_blocks = setup.system.index.element;
  const int num_elements = static_cast<int>(tets.size());
  element_terms_.resize(num_elements);
  invert(
      setup.model.num_nodes, 4 * num_elements, [&tets](int t) { return tets[t / 4][t % 4]; },
      node_corner_start_, node_corners_);
  invert(
      static_cast<int>(setup.system.A.blocks.size()), 16 * num_elements,
      [&element_blocks](int t) { return element_blocks[t / 16][t % 16]; }, block_term_start_,
      block_terms_);
}

void ThreadedElements::pass(const ch08::StepInput& in, const State& state, ch08::System& system) {
  if (parallelism_ == ElementParallelism::gather)
    pass_gather(in, state, system);
  else
    pass_colouring(in, state, system);
}

void ThreadedElements::pass_gather(const ch08::StepInput& in, const State& state,
                                   ch08::System& system) {
  const auto& tets = in.model.tets;
  const int num_elements = static_cast<int>(tets.size());
  const RowChunks& chunks = colouring_.chunks();
  long long fallbacks = 0;
  auto& A = system.A;
  auto& b = system.b;
  run_parallel([&] {
    long long my_fallbacks = 0;  // this thread's: added to the total once, at the end
    // Every element on its own: its terms go to its own slots, nothing is shared.
    for (const int e : StaticShare(num_elements))
      elements_.terms(e, tets[e], state, my_fallbacks, element_terms_[e]);
    // Every row sums its terms, in element order: b_i over the corners at node i, each
    // block over the element blocks that land on it.
    for (const int c : StaticShare(chunks.count())) {
      for (int i = chunks.start[c]; i < chunks.start[c + 1]; ++i) {
        Eigen::Vector3d sum = b.segment<3>(3 * i);
        for (int k = node_corner_start_[i]; k < node_corner_start_[i + 1]; ++k)
          sum += element_terms_[node_corners_[k] / 4].rhs.col(node_corners_[k] % 4);
        b.segment<3>(3 * i) = sum;
      }
      for (int k = A.row_start[chunks.start[c]]; k < A.row_start[chunks.start[c + 1]]; ++k) {
        Eigen::Matrix3d sum = A.blocks[k];
        for (int t = block_term_start_[k]; t < block_term_start_[k + 1]; ++t) {
          const PairOf from = kPairOf[block_terms_[t] % 16];
          const Eigen::Matrix3d& K = element_terms_[block_terms_[t] / 16].K[from.pair];
          if (from.transposed)
            sum += K.transpose();
          else
            sum += K;
        }
        A.blocks[k] = sum;
      }
    }
    add_count(fallbacks, my_fallbacks);
  });
  elements_.end_pass(fallbacks);
}

void ThreadedElements::pass_colouring(const ch08::StepInput& in, const State& state,
                                      ch08::System& system) {
  const auto& tets = in.model.tets;
  const auto& element_blocks = system.index.element;
  auto& A = system.A;
  auto& b = system.b;
  elements_.end_pass(colouring_.for_coloured_groups([&](int first, int last, long long& fallbacks) {
    ch08::ElementTerms terms;
    for (int e = first; e < last; ++e) {
      elements_.terms(e, tets[e], state, fallbacks, terms);
      ch08::scatter(tets[e], element_blocks[e], terms, A, b);
    }
  }));
}

}  // namespace fem::ch09
