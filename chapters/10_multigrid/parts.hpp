// Chapter 10's parts: one V-cycle of smoothed-aggregation multigrid (multigrid.hpp) as the
// PCG's preconditioner, the one Tamstorf, Jones & McCormick 2015 pair with their PPCG, and the
// solve's guess extrapolated from the last solutions.
#pragma once

#include <Eigen/Core>
#include <ostream>

#include "chapters/08_element_kernels/step.hpp"
#include "chapters/10_multigrid/multigrid.hpp"

namespace fem::ch10 {

// Preconditioner: the hierarchy, set up once from the mesh (analyze_pattern: aggregates,
// rigid-body modes at the rest positions, patterns), its finest level refreshed every solve
// and its coarse levels every few (factorize, in prepare), one V-cycle per PCG iteration from a
// zero guess (apply).
class MultigridPreconditioner final : public ch08::PreconditionerPart {
 public:
  using Params = MultigridSettings;  // check(params) throws std::invalid_argument
  static constexpr const char* kName = "one V-cycle of smoothed-aggregation multigrid";
  static constexpr std::string_view kChapter = FEM_PART_CHAPTER;

  MultigridPreconditioner(const ch08::PartSetup& setup, const Params& params);
  void prepare(const ch07::BlockSparseMatrix& A) override;
  void apply(const Eigen::VectorXd& r, Eigen::VectorXd& s) override;
  void set_constraints(const std::vector<NodeConstraint>& constraints) override {
    multigrid_.set_constraints(constraints);
  }
  Multigrid& multigrid() { return multigrid_; }
  const Multigrid& multigrid() const { return multigrid_; }
  // The hierarchy it built: per level its rows, blocks and bytes.
  void describe(std::ostream& out) const;

 private:
  Multigrid multigrid_;
};

// Guess: the polynomial through the last order + 1 solutions, one step ahead.
class Extrapolation {
 public:
  struct Params {
    // 0: the last solution, chapter 09's warm start; 1: 2 y_n - y_(n-1); 2: 3 y_n - 3 y_(n-1)
    // + y_(n-2). Throws std::invalid_argument outside 0..2.
    int order = 2;
  };
  static constexpr const char* kName = "extrapolated from the last three solutions";
  static constexpr std::string_view kChapter = FEM_PART_CHAPTER;

  Extrapolation(const ch08::PartSetup& setup, const Params& params);
  void guess(Eigen::VectorXd& y);

 private:
  int order_;                   // 0, 1 or 2
  Eigen::VectorXd history_[2];  // the solutions of the two steps before the last
  int solves_ = 0;
};

// The settings of chapter 10's step as the lessons and tests vary them.
struct MultigridStepperSettings {
  MultigridSettings multigrid;
  int extrapolation = 2;  // the guess's order (Extrapolation::Params)
};

// check(settings.multigrid) and the extrapolation's order; throws std::invalid_argument.
void check(const MultigridStepperSettings& settings);

// A recipe's parameters with these settings, for any recipe with chapter 10's guess and a
// preconditioner on MultigridSettings (chapters 10-13).
template <class Recipe>
ch08::StepParams<Recipe> multigrid_params(const MultigridStepperSettings& settings) {
  ch08::StepParams<Recipe> params;
  params.guess.order = settings.extrapolation;
  params.preconditioner = settings.multigrid;
  return params;
}

}  // namespace fem::ch10
