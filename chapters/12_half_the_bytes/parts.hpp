// Chapter 12's parts: the element pass across elements (element_batch.hpp), a batch of
// elements per vector register where Eigen's fixed-size 3x3 types leave most lanes empty; and
// chapter 10's V-cycle with its numbers stored in float (reduced_v_cycle.hpp), so that the
// preconditioner streams half the bytes inside chapter 09's double-precision PCG.
#pragma once

#include <ostream>

#include "chapters/08_element_kernels/step.hpp"
#include "chapters/09_threads/threaded_elements.hpp"
#include "chapters/10_multigrid/parts.hpp"
#include "chapters/12_half_the_bytes/element_batch.hpp"
#include "chapters/12_half_the_bytes/reduced_v_cycle.hpp"

namespace fem::ch12 {

// Elements: chapter 09's colouring (chapter 11's slabs), each group in batches of kLanes.
class BatchedElementPass {
 public:
  struct Params {};
  static constexpr const char* kName = "element pass in batches of one element per lane";
  static constexpr std::string_view kChapter = FEM_PART_CHAPTER;

  BatchedElementPass(const ch08::PartSetup& setup, const Params&);
  void start_system(const ch08::StepInput& in, const State& state, ch08::System& system) const {
    colouring_.start_system(in, state, system);
  }
  void pass(const ch08::StepInput& in, const State& state, ch08::System& system);

  const BatchedElements& batched_elements() const { return batched_; }
  const ch09::ElementColouring& colouring() const { return colouring_; }
  int colours() const { return colouring_.colours(); }

 private:
  ch09::ElementColouring colouring_;
  BatchedElements batched_;
};

// Preconditioner: chapter 10's hierarchy, set up and factorized in double as before, applied
// through a copy of its numbers in float: in float arithmetic (Real = float, Arithmetic::single)
// or widened to double in registers (Real = double, Arithmetic::double_on_float).
template <class Real>
class ReducedMultigrid final : public ch08::PreconditionerPart {
 public:
  using Params = ch10::MultigridSettings;
  static constexpr const char* kName = std::is_same_v<Real, float>
                                           ? "one V-cycle on float numbers, in float"
                                           : "one V-cycle on float numbers, in double";
  static constexpr std::string_view kChapter = FEM_PART_CHAPTER;
  static constexpr Arithmetic kArithmetic =
      std::is_same_v<Real, float> ? Arithmetic::single : Arithmetic::double_on_float;

  ReducedMultigrid(const ch08::PartSetup& setup, const Params& params)
      : hierarchy_(setup, params), reduced_(hierarchy_.multigrid()) {}
  // Chapter 10's factorize in double, then the new numbers into float; one cycle in Real.
  void prepare(const ch07::BlockSparseMatrix& A) override { reduced_.prepare(A); }
  void apply(const Eigen::VectorXd& r, Eigen::VectorXd& s) override { reduced_.apply(r, s); }
  // The hierarchy set up again; its next refresh converts the new prolongators into float.
  void set_constraints(const std::vector<NodeConstraint>& constraints) override {
    hierarchy_.set_constraints(constraints);
  }
  ReducedVCycle<Real>& v_cycle() { return reduced_; }
  ch10::Multigrid& multigrid() { return hierarchy_.multigrid(); }
  const ch10::Multigrid& multigrid() const { return hierarchy_.multigrid(); }
  void describe(std::ostream& out) const {
    hierarchy_.describe(out);
    out << "    in float: " << reduced_.number_bytes() / 1024 << " KiB of numbers\n";
  }

 private:
  ch10::MultigridPreconditioner hierarchy_;  // chapter 10's, in double
  ReducedVCycle<Real> reduced_;              // reads hierarchy_: declared after it
};

}  // namespace fem::ch12
