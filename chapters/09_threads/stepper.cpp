// Chapter 09: one linearized backward Euler step (Baraff & Witkin 1998),
//   A dv = b,  A = M - h df/dv - h^2 df/dx,  b = h (f + h df/dx v),
// with velocity constraints by the filter S of the PPCG method (Tamstorf et al. 2015):
//   (S A S^T + I - S) y = S (b - A z),  dv = y + z.
// Chapter 09 changes who does the work: every phase but the constraints runs on all the
// threads OpenMP is given. Three rules keep it correct and the result independent of the
// thread count:
//  - a thread writes only what it owns: the rows of its chunks, or its elements' slots;
//  - every parallel loop over rows goes over the same fixed chunks (RowChunks);
//  - a sum over the mesh is a sum of per-chunk sums added in chunk order, never an
//    OpenMP reduction (whose order of combination OpenMP leaves unspecified).
#include "chapters/09_threads/stepper.hpp"

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <numeric>

#include "chapters/09_threads/parallel.hpp"
#include "common/threads.hpp"

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

ThreadsStepper::ThreadsStepper(const Scene& scene, const SolverSettings& settings,
                               ElementParallelism element_parallelism)
    : ElementKernelsStepper(scene, settings),
      element_parallelism_(element_parallelism),
      chunks_(system_matrix()),
      parallel_pcg_(system_matrix(), scene.constraints),
      block_jacobi_(index_.diagonal) {
  if (element_parallelism_ == ElementParallelism::gather)
    build_gather_tables();
  else
    colour_element_groups(kGroup);
  const char* adaptive = std::getenv("FEM_ADAPTIVE_TEAM");
  adaptive_team_.set_enabled(!(adaptive && std::strcmp(adaptive, "0") == 0));
}

void ThreadsStepper::step(State& state) {
  // The program's count is OpenMP's (--threads, OMP_NUM_THREADS); a step on another team sets
  // it for this thread's regions during the step and puts it back.
  const int given = max_threads();
  // libgomp mallocs a thread's ICV block at its first omp_set_num_threads, once (gomp_icv in
  // libgomp's icv.c): make it in the first step, which the zero-allocation rule leaves out,
  // not in the first step that switches the team.
  if (!steps_taken_++) set_threads(given);
  const int team = adaptive_team_.next(given);
  if (team != given) set_threads(team);
  ElementKernelsStepper::step(state);
  if (team != given) set_threads(given);
  adaptive_team_.record(profile_.step.seconds);
}

void ThreadsStepper::use_preconditioner(Preconditioner& preconditioner, const char* chapter) {
  preconditioner_ = &preconditioner;
  chapter_ = chapter;
}

void ThreadsStepper::build_gather_tables() {
  // The element-to-block table read the other way round, by node and by block. Filled in
  // element order, so that each sum adds in the serial pass's order.
  const int num_elements = static_cast<int>(model_.tets.size());
  element_terms_.resize(num_elements);
  invert(
      model_.num_nodes, 4 * num_elements, [this](int t) { return model_.tets[t / 4][t % 4]; },
      node_corner_start_, node_corners_);
  invert(
      static_cast<int>(system_matrix().blocks.size()), 16 * num_elements,
      [this](int t) { return index_.element[t / 16][t % 16]; }, block_term_start_, block_terms_);
}

void ThreadsStepper::colour_element_groups(int group) {
  // Groups of consecutive elements rather than single elements: a group keeps the mesh
  // order's locality (its elements share nodes, hence cache lines).
  group_ = std::max(1, group);
  const std::vector<int> colour = colour_groups(model_.tets, model_.num_nodes, group_);
  const int colours = colour.empty() ? 0 : 1 + *std::max_element(colour.begin(), colour.end());
  invert(
      colours, static_cast<int>(colour.size()), [&colour](int g) { return colour[g]; },
      colour_start_, colour_order_);
}

void ThreadsStepper::element_pass(const State& state) {
  if (element_parallelism_ == ElementParallelism::gather)
    element_pass_gather(state);
  else
    element_pass_colouring(state);
}

void ThreadsStepper::start_system(const State& state) {
  const double h = scene_.dt, alpha = scene_.damping.alpha;
  // What the elements do not touch: A = (1 + h alpha) M, b = h (f_gravity - alpha M v + f_ext),
  // row by row on the thread that owns the row.
  const double mass_factor = 1.0 + h * alpha;
  auto& A = system_to_write();
  auto& b = rhs_to_write();
  run_parallel([&] {
    for (const int c : StaticShare(chunks_.count())) {
      for (int k = A.row_start[chunks_.start[c]]; k < A.row_start[chunks_.start[c + 1]]; ++k)
        A.blocks[k].setZero();
      for (int i = chunks_.start[c]; i < chunks_.start[c + 1]; ++i)
        A.blocks[index_.diagonal[i]].diagonal() =
            mass_factor * model_.lumped_mass.segment<3>(3 * i);
      const int first = chunks_.first_dof(c), size = chunks_.dofs(c);
      b.segment(first, size).noalias() =
          h * model_.gravity_force.segment(first, size) -
          (h * alpha) *
              model_.lumped_mass.segment(first, size).cwiseProduct(state.v.segment(first, size));
    }
  });
  b += h * f_ext_;  // a few nonzeros, added into a dense vector: not worth a thread
}

void ThreadsStepper::element_pass_gather(const State& state) {
  const int num_elements = static_cast<int>(model_.tets.size());
  long long fallbacks = 0;
  auto& A = system_to_write();
  auto& b = rhs_to_write();
  run_parallel([&] {
    long long my_fallbacks = 0;  // this thread's: added to the total once, at the end
    // Every element on its own: its terms go to its own slots, nothing is shared.
    for (const int e : StaticShare(num_elements))
      elements_.terms(e, model_.tets[e], state, my_fallbacks, element_terms_[e]);
    // Every row sums its terms, in element order: b_i over the corners at node i, each
    // block over the element blocks that land on it.
    for (const int c : StaticShare(chunks_.count())) {
      for (int i = chunks_.start[c]; i < chunks_.start[c + 1]; ++i) {
        Eigen::Vector3d sum = b.segment<3>(3 * i);
        for (int k = node_corner_start_[i]; k < node_corner_start_[i + 1]; ++k)
          sum += element_terms_[node_corners_[k] / 4].rhs.col(node_corners_[k] % 4);
        b.segment<3>(3 * i) = sum;
      }
      for (int k = A.row_start[chunks_.start[c]]; k < A.row_start[chunks_.start[c + 1]]; ++k) {
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

void ThreadsStepper::element_pass_colouring(const State& state) {
  auto& A = system_to_write();
  auto& b = rhs_to_write();
  elements_.end_pass(for_coloured_groups([&](int first, int last, long long& fallbacks) {
    ch08::ElementTerms terms;
    for (int e = first; e < last; ++e) {
      elements_.terms(e, model_.tets[e], state, fallbacks, terms);
      ch08::scatter(model_.tets[e], index_.element[e], terms, A, b);
    }
  }));
}

void ThreadsStepper::solve() {
  // Warm start: y_ still holds the previous step's answer; the solver filters it.
  const SolveStats result = solve_filtered_system(y_);
  dv_ = y_;
  dv_ += z_;
  profile_.record(result);
  report_if_not_converged(profile_, settings_, chapter_, warned_not_converged_);
}

SolveStats ThreadsStepper::solve_filtered_system(Eigen::VectorXd& y) {
  return parallel_pcg_.solve(system_matrix(), *preconditioner_, filtered_b_, settings_, y);
}

}  // namespace fem::ch09
