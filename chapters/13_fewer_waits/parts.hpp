// Chapter 13's parts: chapter 12's float V-cycle run in fewer parallel loops (fused_v_cycle.hpp),
// inside a PCG with one wait per reduction (single_reduction_pcg.hpp): every loop ends at a
// barrier where each thread waits for the slowest, and a loop whose work reads only its own
// rows can run inside the loop before it.
#pragma once

#include <optional>
#include <ostream>
#include <type_traits>
#include <utility>
#include <vector>

#include "chapters/08_element_kernels/step.hpp"
#include "chapters/09_threads/parallel_pcg.hpp"
#include "chapters/12_half_the_bytes/parts.hpp"
#include "chapters/13_fewer_waits/fused_v_cycle.hpp"
#include "chapters/13_fewer_waits/single_reduction_pcg.hpp"

namespace fem::ch13 {

// Preconditioner: chapter 12's float hierarchy, its cycle run by fused loops.
class FusedPreconditioner final : public ch08::PreconditionerPart {
 public:
  using Params = ch10::MultigridSettings;
  static constexpr const char* kName = "one V-cycle on float numbers, its loops fused";
  static constexpr std::string_view kChapter = FEM_PART_CHAPTER;

  FusedPreconditioner(const ch08::PartSetup& setup, const Params& params)
      : reduced_(setup, params), fused_(reduced_.v_cycle(), reduced_.multigrid()) {}
  void prepare(const ch07::BlockSparseMatrix& A) override { fused_.prepare(A); }
  void apply(const Eigen::VectorXd& r, Eigen::VectorXd& s) override { fused_.apply(r, s); }
  void set_constraints(const std::vector<NodeConstraint>& constraints) override {
    reduced_.set_constraints(constraints);
  }
  // Its cycle in two parts (enter, complete), which a solver may run inside loops of its own
  // (SingleReductionSolver asks for it at compile time).
  FusedVCycle& fused_cycle() { return fused_; }
  ch12::ReducedMultigrid<float>& reduced() { return reduced_; }
  ch10::Multigrid& multigrid() { return reduced_.multigrid(); }
  const ch10::Multigrid& multigrid() const { return reduced_.multigrid(); }
  void describe(std::ostream& out) const { reduced_.describe(out); }

 private:
  ch12::ReducedMultigrid<float> reduced_;  // chapter 12's levels and their conversion
  FusedVCycle fused_;                      // reads reduced_: declared after it
};

// Whether a preconditioner part offers its cycle in two parts, fused_cycle() (chapter 13's).
template <class Part, class = void>
struct HasFusedCycle : std::false_type {};
template <class Part>
struct HasFusedCycle<Part, std::void_t<decltype(std::declval<Part&>().fused_cycle())>>
    : std::true_type {};

// Solver: Chronopoulos and Gear's PCG on a fused cycle; chapter 09's PCG with any other
// preconditioner, or where the hierarchy has nothing to fuse (one level, or a finest level on
// one thread).
class SingleReductionSolver {
 public:
  struct Params {};
  static constexpr const char* kName = "single-reduction PCG (Chronopoulos and Gear)";
  static constexpr std::string_view kChapter = FEM_PART_CHAPTER;

  SingleReductionSolver(const ch08::PartSetup& setup, const Params&)
      : constraints_(setup.scene.constraints), parallel_(setup.system.A, setup.scene.constraints) {}
  template <class Preconditioner>
  SolveStats solve(ch08::System& system, ch08::ProductPart& product, Preconditioner& preconditioner,
                   const SolverSettings& settings) {
    if constexpr (HasFusedCycle<Preconditioner>::value) {
      FusedVCycle& M = preconditioner.fused_cycle();
      if (M.fused())
        return single_reduction(M).solve(system.A, product, M, system.filtered_b, settings,
                                         system.y);
    }
    return parallel_.solve(system.A, product, preconditioner, system.filtered_b, settings,
                           system.y);
  }
  void set_constraints(const std::vector<NodeConstraint>& constraints) {
    if (single_reduction_) single_reduction_->set_constraints(constraints);
    parallel_.set_constraints(constraints);
  }
  // Made at the first solve on a fused cycle: its sums run over the cycle's finest row blocks.
  SingleReductionPcg* single_reduction() {
    return single_reduction_ ? &*single_reduction_ : nullptr;
  }

 private:
  SingleReductionPcg& single_reduction(FusedVCycle& M) {
    if (!single_reduction_) single_reduction_.emplace(M.fine_part(), constraints_);
    return *single_reduction_;
  }

  const std::vector<NodeConstraint>& constraints_;  // the order's scene's
  std::optional<SingleReductionPcg> single_reduction_;
  ch09::ParallelPcg parallel_;  // where nothing is fused
};

}  // namespace fem::ch13
