// Chapter 08's building block: the element loop at the speed of its arithmetic. The
// rotation by Newton's method warm-started from the last steps' rotations (instead of an SVD),
// the blocks of -df/dx in closed form from the shape gradients (instead of R K0 R^T with a
// stored K0), and the fused terms of one element: what it adds to b and to A.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "chapters/07_block_sparse/block_sparse.hpp"
#include "common/model.hpp"

namespace fem::ch08 {

// What the fused pass reads per element: 88 bytes instead of common/'s 1.3 KB ElementRest.
struct ElementShape {
  Eigen::Matrix3d Dm_inv;  // F = Ds Dm^-1; its rows are the shape gradients g_1, g_2, g_3
  double mu_volume;        // V mu
  double lambda_volume;    // V lambda
};
ElementShape make_element_shape(const ElementRest& rest, const Lame& lame);

// Newton's decisions, shared by every loop that computes these rotations (element by element
// or several elements at once), so that each decides as newton_polar_rotation does.
namespace newton {
// Below this det F / (|F|^2 / 3)^(3/2) (1 for a rotation, 0 for a flat element) Newton is
// not asked: an inverted element's polar rotation has det -1 and common/ flips it to +1
// by a convention that only the SVD knows, and near det F = 0 the sign itself is rounding.
constexpr double kMinRelativeDet = 1e-4;
// Below det H = kMinRelativeHessianDet |q|^6 (|F|^2 / 3)^(3/2) (H carries |q|^2 and |F|),
// H is taken as singular: no Newton step.
constexpr double kMinRelativeHessianDet = 1e-12;
// Newton converges quadratically: once a step is below 1e-8 rad, the next would be below
// about 1e-16, rounding. The cap stops a start far from the answer (then the SVD decides).
constexpr double kConvergedStep = 1e-8;
constexpr int kMaxIterations = 12;
}  // namespace newton

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
// With `iterations`, Newton's iterations go there (0 where it did not decide).
Eigen::Matrix3d fast_polar_rotation(const Eigen::Matrix3d& F, Eigen::Quaterniond& q,
                                    long long& fallbacks, int* iterations = nullptr);

// The Newton iterations an element pass ran, for the roofline's flops as executed: one count
// per OpenMP thread number, each on its own cache line (no thread writes a line another
// writes, so counting costs an add per element and no sharing), summed only when asked.
class IterationCounter {
 public:
  void add(long long n) {
#ifdef _OPENMP
    slots_[omp_get_thread_num() % kSlots].n += n;
#else
    slots_[0].n += n;
#endif
  }
  long long total() const {
    long long sum = 0;
    for (const Slot& s : slots_) sum += s.n;
    return sum;
  }

 private:
  static constexpr int kSlots = 64;  // thread numbers beyond share slots: keep teams <= 64
  struct alignas(64) Slot {
    long long n = 0;
  };
  std::array<Slot, kSlots> slots_{};
};

// The ten distinct blocks K_ab, a <= b, of K = R K0 R^T = -df/dx_e in closed form, with
// r_a = R g_a (columns of r) and K0 never formed:
//   K_ab = V [mu (r_a . r_b) I + mu r_b r_a^T + lambda r_a r_b^T],  K_ba = K_ab^T.
// The scale s multiplies both Lame terms (the fused pass passes h beta + h^2).
constexpr std::array<std::array<int, 2>, 10> kUpperPairs = {
    {{0, 0}, {0, 1}, {0, 2}, {0, 3}, {1, 1}, {1, 2}, {1, 3}, {2, 2}, {2, 3}, {3, 3}}};
void stiffness_blocks(const Eigen::Matrix<double, 3, 4>& r, double mu_volume, double lambda_volume,
                      std::array<Eigen::Matrix3d, 10>& K);

// r_a = R g_a, the rotated shape gradients, for a = 0..3.
Eigen::Matrix<double, 3, 4> rotated_gradients(const Eigen::Matrix3d& R,
                                              const Eigen::Matrix3d& Dm_inv);

// What one element adds to the system: its terms of b (a column per corner) and its ten
// distinct blocks of A (kUpperPairs).
struct ElementTerms {
  Eigen::Matrix<double, 3, 4> rhs;
  std::array<Eigen::Matrix3d, 10> K;
};

// The element loop's state and its fused kernel: the shapes, and per element the rotations
// of the last two steps (the next step's warm start).
class FusedElements {
 public:
  FusedElements() = default;
  FusedElements(const Model& model, const Scene& scene);

  // Element e with corners t: its rotation (by Newton from the one predicted by the last two
  // steps', or the SVD where Newton cannot decide: ++fallbacks), its terms of b,
  //   h f_e + h df/dx_e ((h + beta) v_e),
  // and its blocks of (h beta + h^2) K_e. Writes only element e's rotations, so elements can
  // be computed in any order, on any thread.
  void terms(int e, const Eigen::Vector4i& t, const State& state, long long& fallbacks,
             ElementTerms& out);
  // Once every element of the step is done: the next step extrapolates the rotations.
  void end_pass(long long fallbacks);

  const std::vector<ElementShape>& shapes() const { return shapes_; }
  const std::vector<Eigen::Quaterniond>& rotations() const { return rotations_; }
  const std::vector<Eigen::Quaterniond>& previous_rotations() const { return previous_rotations_; }
  // Elements whose rotation came from the SVD because Newton could not decide: in the last
  // step, and in all steps so far.
  long long last_step_fallbacks() const { return last_step_fallbacks_; }
  long long total_fallbacks() const { return total_fallbacks_; }
  // Rotations computed and Newton iterations run, in all steps so far.
  long long total_rotations() const { return total_rotations_; }
  long long total_newton_iterations() const { return iterations_.total(); }

 private:
  double h_ = 0.0;
  double velocity_scale_ = 0.0;  // b's df/dx term acts on (h + beta) v
  double stiffness_ = 0.0;       // A = ... - (h beta + h^2) df/dx
  std::vector<ElementShape> shapes_;
  std::vector<Eigen::Quaterniond> rotations_;           // R_e of the last step
  std::vector<Eigen::Quaterniond> previous_rotations_;  // R_e of the step before
  bool first_step_ = true;
  long long last_step_fallbacks_ = 0, total_fallbacks_ = 0, total_rotations_ = 0;
  IterationCounter iterations_;
};

// b += the element's terms, A += its blocks: ten computed, sixteen written (K_ba = K_ab^T),
// at the element's blocks of the pattern.
void scatter(const Eigen::Vector4i& t, const std::array<int, 16>& blocks, const ElementTerms& terms,
             ch07::BlockSparseMatrix& A, Eigen::VectorXd& b);

}  // namespace fem::ch08
