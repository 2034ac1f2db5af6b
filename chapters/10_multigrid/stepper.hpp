// Chapter 10: the solve stops growing with the mesh. The threaded step of before (the fused
// element pass, the block SpMV over fixed row chunks, sums in chunk order), with one V-cycle
// of smoothed-aggregation multigrid (multigrid.hpp) as the PCG's preconditioner in place of
// block Jacobi: the preconditioner of Tamstorf, Jones & McCormick 2015, the poster's source
// for PPCG. The V-cycle runs on one thread, so the result is still the same to the last bit
// for any thread count.
#pragma once

#include <Eigen/Geometry>
#include <Eigen/SparseCore>
#include <array>
#include <optional>
#include <vector>

#include "chapters/10_multigrid/multigrid.hpp"
#include "common/model.hpp"
#include "common/stepper.hpp"

namespace fem::ch10 {

// ---- the element kernels ------------------------------------------------------------

// What the fused pass reads per element: 88 bytes instead of common/'s 1.3 KB ElementRest.
struct ElementShape {
  Eigen::Matrix3d Dm_inv;  // F = Ds Dm^-1; its rows are the shape gradients g_1, g_2, g_3
  double mu_volume;        // V mu
  double lambda_volume;    // V lambda
};
ElementShape make_element_shape(const ElementRest& rest, const Lame& lame);

// The rotation of the polar decomposition F = R S by Newton's method on the rotations,
// started from q (the warm start: predicted from the last steps' rotations) and written
// back to q.
// Returns the number of iterations, or -1 where Newton cannot decide: F inverted, flat or
// collapsed (det F too small against |F|^3), or an iterate outside the basin of the polar
// rotation (where R^T F is not positive definite enough to give a Newton step), or no
// convergence within the iteration cap. q is unusable after -1.
int newton_polar_rotation(const Eigen::Matrix3d& F, Eigen::Quaterniond& q);

// Newton's start: the rotation extrapolated at constant angular velocity from the last two
// steps', R_k R_{k-1}^T R_k. Its error is the change of the angular velocity, second order
// in the time step, where the last rotation alone is first order: one Newton iteration less.
inline Eigen::Quaterniond predicted_rotation(const Eigen::Quaterniond& last,
                                             const Eigen::Quaterniond& before) {
  return last * before.conjugate() * last;
}

// The rotation common/'s polar_rotation returns (to 1e-12 per entry, the tests), by Newton
// from q where it decides, and by common/'s SVD where it does not (then ++fallbacks). q
// holds the answer on exit, the next step's warm start.
Eigen::Matrix3d fast_polar_rotation(const Eigen::Matrix3d& F, Eigen::Quaterniond& q,
                                    long long& fallbacks);

// The ten distinct blocks K_ab, a <= b, of K = R K0 R^T = -df/dx_e in closed form, with
// r_a = R g_a (columns of r) and K0 never formed:
//   K_ab = V [mu (r_a . r_b) I + mu r_b r_a^T + lambda r_a r_b^T],  K_ba = K_ab^T.
// The scale s multiplies both Lame terms (the fused pass passes h beta + h^2).
constexpr std::array<std::array<int, 2>, 10> kUpperPairs = {
    {{0, 0}, {0, 1}, {0, 2}, {0, 3}, {1, 1}, {1, 2}, {1, 3}, {2, 2}, {2, 3}, {3, 3}}};
void stiffness_blocks(const Eigen::Matrix<double, 3, 4>& r, double mu_volume,
                      double lambda_volume, std::array<Eigen::Matrix3d, 10>& K);

// r_a = R g_a, the rotated shape gradients, for a = 0..3.
Eigen::Matrix<double, 3, 4> rotated_gradients(const Eigen::Matrix3d& R,
                                              const Eigen::Matrix3d& Dm_inv);

// ---- the block sparse matrix -----------------------------------------------------

// Block compressed-row storage: row i (node i) holds blocks row_start[i] .. row_start[i+1]-1,
// block k is blocks[k] at block column column[k], columns sorted within a row.
struct BlockSparseMatrix {
  std::vector<int> row_start;
  std::vector<int> column;
  std::vector<Eigen::Matrix3d> blocks;

  BlockSparseMatrix() = default;
  // The pattern of a symmetric node adjacency (each row sorted, the node itself included).
  explicit BlockSparseMatrix(const std::vector<std::vector<int>>& adjacency);

  int block_rows() const { return static_cast<int>(row_start.size()) - 1; }
  // Index of block (i, j) in blocks, found by a binary search: for set-up only.
  int find(int i, int j) const;
  // y_i = sum_j A_ij x_j for the rows [first, last): each y_i written once, by one thread.
  void multiply_rows(const Eigen::VectorXd& x, Eigen::VectorXd& y, int first, int last) const;
  // y = A x on the calling thread.
  void multiply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const;
  // y = A x reading only the blocks with j >= i (A must be symmetric): y_i += A_ij x_j and
  // y_j += A_ij^T x_i. Half the blocks read, but y is scattered.
  void multiply_upper(const Eigen::VectorXd& x, Eigen::VectorXd& y) const;
  // The same matrix with only the blocks j >= i: symmetric storage.
  BlockSparseMatrix upper() const;
  // Conversion for tests and comparisons (allocates).
  Eigen::SparseMatrix<double> to_sparse() const;
};

// The fixed partition of the node rows that every parallel loop over rows and every sum
// uses: up to 64 chunks of about the same number of blocks, whatever the thread count.
// Threads take whole chunks (a static schedule); a sum over the mesh is the sum of per-chunk
// sums, added in chunk order: the same additions in the same order for any thread count.
struct RowChunks {
  static constexpr int kMaxCount = 64, kMinRows = 32;
  std::vector<int> start;  // chunk c holds rows start[c] .. start[c+1]-1

  RowChunks() = default;
  explicit RowChunks(const BlockSparseMatrix& pattern);
  int count() const { return static_cast<int>(start.size()) - 1; }
  int rows(int c) const { return start[c + 1] - start[c]; }
};

struct PcgResult {
  int iterations = 0;
  double relative_residual = 0.0;  // ||b - A y|| / ||b||, as Eigen's error()
  bool converged = false;
};

// CG on the filtered block system preconditioned by one V-cycle, with the same stopping rule
// and PPCG filter as chapter 06, in one parallel region. Set up once per pattern and set
// of constraints; the work vectors are sized on the first solve and reused.
class ParallelPcg {
 public:
  ParallelPcg() = default;
  ParallelPcg(const BlockSparseMatrix& pattern, const std::vector<NodeConstraint>& constraints);
  // y holds the initial guess on entry and the solution on exit. The preconditioner must
  // have been prepared for A.
  PcgResult solve(const BlockSparseMatrix& A, Multigrid& preconditioner,
                  const Eigen::VectorXd& b, const SolverSettings& settings, Eigen::VectorXd& y);

 private:
  RowChunks chunks_;
  // The constraints sorted by node: chunk c's are constraints_[constraint_start_[c] ..].
  std::vector<NodeConstraint> constraints_;
  std::vector<int> constraint_start_;
  Eigen::VectorXd r_, s_, p_, q_;
  // Per-chunk partial sums, one array per reduction, so that no array is written again
  // while a slower thread may still be adding it up.
  std::vector<double> partial_bb_, partial_pq_, partial_rr_, partial_rs_;
};

// How the element pass keeps two threads from adding into the same block at once.
enum class ElementParallelism {
  // Each element writes its forces and blocks to its own slots; then the thread that owns
  // a row sums the row's terms, in element order.
  gather,
  // Groups of consecutive elements are coloured so that no two groups of a colour share a
  // node; one colour at a time, the threads scatter as the serial pass does.
  colouring,
};

class MultigridStepper final : public Stepper {
 public:
  MultigridStepper(const Scene& scene, const SolverSettings& settings,
                   const MultigridSettings& multigrid = {},
                   ElementParallelism element_parallelism = ElementParallelism::colouring);
  void step(State& state) override;
  // forces: the fused element pass (rotations, element forces, and the blocks of df/dx
  // written into A and b); dfdx: zero, no df/dx is built; compose: what is left of the
  // composition, A = (1 + h alpha) M and the mass, gravity and interaction terms of b.
  const StepProfile& profile() const override { return profile_; }
  bool uses_threads() const override { return true; }

  // The last step's filtered system S A S^T + I - S and right-hand side S (b - A z).
  const BlockSparseMatrix& system_matrix() const { return A_; }
  const Eigen::VectorXd& system_rhs() const { return filtered_b_; }
  const std::vector<int>& diagonal_blocks() const { return diagonal_block_; }
  // Per element, the rotations of the last two steps (the next step's warm start).
  const std::vector<Eigen::Quaterniond>& rotations() const { return rotations_; }
  const std::vector<Eigen::Quaterniond>& previous_rotations() const { return previous_rotations_; }
  const std::vector<ElementShape>& shapes() const { return shapes_; }
  // Elements whose rotation came from the SVD because Newton could not decide: in the
  // last step, and in all steps so far.
  long long last_step_fallbacks() const { return last_step_fallbacks_; }
  long long total_fallbacks() const { return total_fallbacks_; }
  int colours() const { return static_cast<int>(colour_start_.size()) - 1; }
  const Multigrid& multigrid() const { return *multigrid_; }
  Multigrid& multigrid() { return *multigrid_; }

 private:
  void start_system(const State& state);
  void element_pass(const State& state);
  void element_pass_gather(const State& state);
  void element_pass_colouring(const State& state);
  // The element's rotation, its terms of b, and its ten blocks scaled for A.
  void element_terms(int e, const State& state, long long& fallbacks,
                     Eigen::Matrix<double, 3, 4>& rhs, std::array<Eigen::Matrix3d, 10>& K);
  void apply_constraints(const State& state);
  void solve();

  Scene scene_;
  Model model_;
  SolverSettings settings_;
  ElementParallelism element_parallelism_;
  StepProfile profile_;
  bool warned_not_converged_ = false;

  std::vector<ElementShape> shapes_;
  std::vector<Eigen::Quaterniond> rotations_;           // R_e of the last step
  std::vector<Eigen::Quaterniond> previous_rotations_;  // R_e of the step before
  bool first_step_ = true;
  long long last_step_fallbacks_ = 0, total_fallbacks_ = 0;
  std::vector<std::array<int, 16>> element_blocks_;  // per element: block of (a, b) in A
  RowChunks chunks_;
  // Gather: each element's terms of b and blocks of A; per node, its (element, corner)
  // pairs 4 e + a, and per block its (element, block) pairs 16 e + 4 a + b, in element order.
  std::vector<Eigen::Matrix<double, 3, 4>> element_rhs_;
  std::vector<std::array<Eigen::Matrix3d, 10>> element_K_;
  std::vector<int> node_corner_start_, node_corners_;
  std::vector<int> block_term_start_, block_terms_;
  // Colouring: groups of kGroup consecutive elements, sorted by colour; colour c holds the
  // groups colour_order_[colour_start_[c]] .. colour_order_[colour_start_[c + 1] - 1].
  static constexpr int kGroup = 16;
  std::vector<int> colour_order_, colour_start_;
  BlockSparseMatrix A_;               // M - h df/dv - h^2 df/dx, the mesh's block pattern
  std::vector<int> diagonal_block_;   // per node: index of block (i, i)
  std::vector<int> transpose_block_;  // per block (i, j): index of block (j, i)
  Eigen::VectorXd b_;                 // h (f + h df/dx v)
  Eigen::VectorXd z_;                 // prescribed velocity change of constrained dofs
  Eigen::VectorXd filtered_b_;        // S (b - A z)
  Eigen::VectorXd dv_;
  ParallelPcg pcg_;
  std::optional<Multigrid> multigrid_;  // set up in the constructor, from the pattern of A_
  Eigen::VectorXd y_;  // the unknown of the filtered system, dv = y + z: also the warm start
};

}  // namespace fem::ch10
