// Chapter 09's other parts: the team a step runs on, block Jacobi on the fixed row chunks, and
// the parallel PCG (parallel_pcg.hpp) with any product and any preconditioner part.
#pragma once

#include <Eigen/Core>

#include "chapters/08_element_kernels/serial_parts.hpp"
#include "chapters/08_element_kernels/step.hpp"
#include "chapters/09_threads/adaptive_team.hpp"
#include "chapters/09_threads/parallel_pcg.hpp"

namespace fem::ch09 {

// Team: OpenMP's threads (--threads, OMP_NUM_THREADS), or one thread while that is faster (a
// busy machine: AdaptiveTeam). The state is the same either way.
class TeamOfThreads {
 public:
  static constexpr const char* kName = "every thread, or one while that is faster";
  static constexpr std::string_view kChapter = FEM_PART_CHAPTER;
  static constexpr bool kThreads = true;

  TeamOfThreads();
  template <class Step>
  void run(Step&& step, const double& step_seconds) {
    const int given = begin();
    step();
    end(given, step_seconds);
  }
  // Tests that compare thread counts keep the count they set (off); the environment variable
  // FEM_ADAPTIVE_TEAM=0 turns it off for a whole program (to see what it prevents).
  int threads() const { return adaptive_team_.team(); }  // of the last step, as it ran
  AdaptiveTeam& adaptive_team() { return adaptive_team_; }
  const AdaptiveTeam& adaptive_team() const { return adaptive_team_; }

 private:
  int begin();  // sets this step's team; returns the program's count
  void end(int given, double step_seconds);

  AdaptiveTeam adaptive_team_;
  long long steps_taken_ = 0;
  int team_ = 0;
};

// Preconditioner: chapter 08's block Jacobi, its inverses computed by the whole team, chunk by
// chunk (applied inside the PCG's loops, as any block-diagonal part is).
class JacobiOnChunks final : public ch08::BlockJacobi {
 public:
  static constexpr const char* kName = "block Jacobi on the row chunks";
  static constexpr std::string_view kChapter = FEM_PART_CHAPTER;

  JacobiOnChunks(const ch08::PartSetup& setup, const Params& params)
      : BlockJacobi(setup, params), chunks_(setup.system.A) {}
  // By every thread of the solve's team, each inverting its chunks' diagonal blocks.
  void prepare(const BlockSparseMatrix& A) override;
  // Outside a team (chapter 08's solver, the kernels alone), the whole vector on this thread.
  void apply(const Eigen::VectorXd& r, Eigen::VectorXd& s) override;
  const RowChunks& chunks() const { return chunks_; }

 private:
  RowChunks chunks_;
};

// Solver: the parallel PCG with the recipe's product and preconditioner.
class ParallelPcgSolver {
 public:
  struct Params {};
  static constexpr const char* kName = "parallel PCG, three barriers an iteration";
  static constexpr std::string_view kChapter = FEM_PART_CHAPTER;

  ParallelPcgSolver(const ch08::PartSetup& setup, const Params&)
      : pcg_(setup.system.A, setup.scene.constraints) {}
  SolveStats solve(ch08::System& system, ch08::ProductPart& product,
                   ch08::PreconditionerPart& preconditioner, const SolverSettings& settings) {
    return pcg_.solve(system.A, product, preconditioner, system.filtered_b, settings, system.y);
  }
  void set_constraints(const std::vector<NodeConstraint>& constraints) {
    pcg_.set_constraints(constraints);
  }
  ParallelPcg& pcg() { return pcg_; }

 private:
  ParallelPcg pcg_;
};

}  // namespace fem::ch09
