// Chapter 08's parts: the step on one thread in the mesh's numbering, its fused element pass,
// and chapter 07's block-Jacobi PCG warm-started from the last solution, its product and its
// preconditioner now parts of their own (contract.hpp). Later chapters replace some of them in
// their recipes and keep the others.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "chapters/08_element_kernels/contract.hpp"
#include "chapters/08_element_kernels/element_kernels.hpp"
#include "chapters/08_element_kernels/serial_pcg.hpp"
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
  int threads() const { return 1; }  // of the last step
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

// Product: A's own blocks, as the element pass assembled them (chapter 07's block rows).
class AssembledProduct final : public ProductPart {
 public:
  struct Params {};
  static constexpr const char* kName = "A's 3x3 blocks, as assembled";
  static constexpr std::string_view kChapter = FEM_PART_CHAPTER;

  AssembledProduct(const PartSetup& setup, const Params&) : A_(&setup.system.A) {}
  void prepare(const BlockSparseMatrix& A) override { A_ = &A; }
  void multiply_rows(const Eigen::VectorXd& x, Eigen::VectorXd& y, int first,
                     int last) const override {
    A_->multiply_rows(x, y, first, last);
  }
  const BlockSparseMatrix& matrix() const { return *A_; }

 private:
  const BlockSparseMatrix* A_;
};

// Preconditioner: block Jacobi, s_i = D_i^-1 r_i with D_i the 3x3 diagonal block (chapter 07's),
// its inverses computed once per solve.
class BlockJacobi : public PreconditionerPart {
 public:
  struct Params {};
  static constexpr const char* kName = "block Jacobi";
  static constexpr std::string_view kChapter = FEM_PART_CHAPTER;

  BlockJacobi(const PartSetup& setup, const Params&);
  // By every thread of a solver's team (chapter 09's): one inverts, the others wait at the end
  // of the `omp single` (outside a parallel region it is this thread's loop).
  void prepare(const BlockSparseMatrix& A) override;
  void apply(const Eigen::VectorXd& r, Eigen::VectorXd& s) override;
  bool block_diagonal() const override { return true; }
  void apply_rows(int first, int last, const Eigen::VectorXd& r, Eigen::VectorXd& s) const override;

 protected:
  // The diagonal blocks of the filtered matrix are symmetric positive definite (a fixed
  // node's is the identity): a fixed-size 3x3 inverse each, no search.
  void invert_rows(const BlockSparseMatrix& A, int first, int last);

 private:
  std::vector<int> diagonal_block_;
  std::vector<Eigen::Matrix3d> inverse_diagonal_;  // (A_ii)^-1
};

// Solver: chapter 07's PCG on the filtered block system, one thread, with the recipe's product
// and preconditioner (serial_pcg.hpp).
class SerialPcg {
 public:
  struct Params {};
  static constexpr const char* kName = "the block PCG on one thread";
  static constexpr std::string_view kChapter = FEM_PART_CHAPTER;

  SerialPcg(const PartSetup& setup, const Params&) : constraints_(setup.scene.constraints) {}
  SolveStats solve(System& system, ProductPart& product, PreconditionerPart& preconditioner,
                   const SolverSettings& settings) {
    return serial_pcg(system.A, product, preconditioner, system.filtered_b, constraints_, settings,
                      vectors_, system.y);
  }
  // The constraints are read from the order's scene at every solve: nothing to keep.
  void set_constraints(const std::vector<NodeConstraint>&) {}

 private:
  const std::vector<NodeConstraint>& constraints_;  // the order's scene's
  PcgVectors vectors_;
};

}  // namespace fem::ch08
