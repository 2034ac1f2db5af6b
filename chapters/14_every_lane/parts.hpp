// Chapter 14's part: chapter 12's float V-cycle with its finest level in pair lanes
// (lane_v_cycle.hpp), where two thirds of the interactive step went to one kernel with three of
// a core's four vector lanes idle.
#pragma once

#include <ostream>

#include "chapters/08_element_kernels/step.hpp"
#include "chapters/12_half_the_bytes/parts.hpp"
#include "chapters/14_every_lane/lane_scatter.hpp"
#include "chapters/14_every_lane/lane_v_cycle.hpp"

namespace fem::ch14 {

// Preconditioner: chapter 12's hierarchy in float, its finest level's products in pair lanes.
class LaneMultigrid final : public ch08::PreconditionerPart {
 public:
  using Params = ch10::MultigridSettings;
  static constexpr const char* kName =
      "one V-cycle on float numbers, the finest level in pair lanes";
  static constexpr std::string_view kChapter = FEM_PART_CHAPTER;

  LaneMultigrid(const ch08::PartSetup& setup, const Params& params)
      : reduced_(setup, params), lanes_(reduced_.v_cycle(), reduced_.multigrid()) {}
  void prepare(const ch07::BlockSparseMatrix& A) override { lanes_.prepare(A); }
  void apply(const Eigen::VectorXd& r, Eigen::VectorXd& s) override { lanes_.apply(r, s); }
  void set_constraints(const std::vector<NodeConstraint>& constraints) override {
    reduced_.set_constraints(constraints);
  }
  LaneVCycle& lane_v_cycle() { return lanes_; }
  const LaneVCycle& lane_v_cycle() const { return lanes_; }
  ch12::ReducedMultigrid<float>& reduced() { return reduced_; }
  ch10::Multigrid& multigrid() { return reduced_.multigrid(); }
  const ch10::Multigrid& multigrid() const { return reduced_.multigrid(); }
  void describe(std::ostream& out) const {
    reduced_.describe(out);
    if (lanes_.lanes())
      out << "    finest level in pair lanes, "
          << (lanes_.layout() == Layout::padded ? "padded" : "packed")
          << " (the faster of the two in its first steps on each team size): "
          << lanes_.with_fine_level([](const auto& fine) { return fine.blocks.bytes(); }) / 1024
          << " KiB\n";
  }

 private:
  ch12::ReducedMultigrid<float> reduced_;  // chapter 12's levels and their conversion
  LaneVCycle lanes_;                       // reads reduced_: declared after it
};

}  // namespace fem::ch14
