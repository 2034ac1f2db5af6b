// Chapter 08's parts: the step on one thread in the mesh's numbering, its fused element pass,
// and chapter 07's block-Jacobi PCG warm-started from the last solution. Later chapters
// replace some of them in their recipes and keep the others.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "chapters/07_block_sparse/block_pcg.hpp"
#include "chapters/08_element_kernels/element_kernels.hpp"
#include "chapters/08_element_kernels/step.hpp"

namespace fem::ch08 {

// Order: the mesh's own numbering. The step runs on the caller's state.
class MeshOrder {
 public:
  struct Params {};
  static constexpr const char* kName = "the mesh's numbering";
  static constexpr std::string_view kChapter = FEM_PART_CHAPTER;

  MeshOrder(const Scene& scene, const Params&) : scene_(scene) {}
  const Scene& scene() const { return scene_; }
  void set_constraints(const std::vector<NodeConstraint>& constraints) {
    scene_.constraints = constraints;
  }
  int element_group() const { return 0; }
  template <class Step>
  void step(State& state, Step&& inner) {
    inner(state);
  }
  const std::vector<ExternalForce>& inward(const std::vector<ExternalForce>& forces) const {
    return forces;
  }
  void outward(const Eigen::SparseVector<double>&) {}
  const Eigen::SparseVector<double>& outward_forces(const Eigen::SparseVector<double>& f) const {
    return f;
  }

 private:
  Scene scene_;
};

// Team: one thread, whatever OpenMP is given.
struct OneThread {
  static constexpr const char* kName = "one thread";
  static constexpr std::string_view kChapter = FEM_PART_CHAPTER;
  static constexpr bool kThreads = false;
  template <class Step>
  void run(Step&& step, const double& /*step_seconds*/) {
    step();
  }
};

// Elements: A = (1 + h alpha) M and b's mass, gravity and interaction terms (compose), then one
// pass over the elements that writes their forces and blocks into b and A (forces).
class SerialElements {
 public:
  struct Params {};
  static constexpr const char* kName = "fused element pass";
  static constexpr std::string_view kChapter = FEM_PART_CHAPTER;

  SerialElements(const PartSetup& setup, const Params&);
  void start_system(const StepInput& in, const State& state, System& system) const;
  void pass(const StepInput& in, const State& state, System& system);
  // The element loop's shapes, rotations and counters.
  const FusedElements& fused() const { return elements_; }

 private:
  FusedElements elements_;
};

// Guess: the last solution, which y still holds (a warm start).
struct WarmStart {
  struct Params {};
  static constexpr const char* kName = "the last solution";
  static constexpr std::string_view kChapter = FEM_PART_CHAPTER;
  WarmStart(const PartSetup&, const Params&) {}
  void guess(Eigen::VectorXd&) const {}
};

// Preconditioner: block Jacobi, which chapter 07's PCG computes inside each solve.
struct PcgBlockJacobi {
  struct Params {};
  static constexpr const char* kName = "block Jacobi, inside the block PCG";
  static constexpr std::string_view kChapter = FEM_PART_CHAPTER;
  PcgBlockJacobi(const PartSetup&, const Params&) {}
};

// Solver: chapter 07's PCG on the filtered block system, one thread.
class SerialPcg {
 public:
  static constexpr const char* kName = "the block PCG on one thread";
  static constexpr std::string_view kChapter = FEM_PART_CHAPTER;

  SerialPcg(const PartSetup& setup, PcgBlockJacobi&) : constraints_(setup.scene.constraints) {}
  SolveStats solve(System& system, PcgBlockJacobi&, const SolverSettings& settings) {
    return ch07::pcg_solve(system.A, system.index.diagonal, system.filtered_b, constraints_,
                           settings, pcg_, system.y);
  }
  // The constraints are read from the order's scene at every solve: nothing to keep.
  void set_constraints(const std::vector<NodeConstraint>&) {}
  const ch07::PcgWorkspace& workspace() const { return pcg_; }

 private:
  const std::vector<NodeConstraint>& constraints_;  // the order's scene's
  ch07::PcgWorkspace pcg_;
};

}  // namespace fem::ch08
