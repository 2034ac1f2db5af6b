// Chapter 12's element pass: chapter 08's fused element terms computed for kLanes elements
// at once, one element per lane of a vector register. A 3x3 product in Eigen's fixed-size
// types is 27 multiply-adds on vectors of 3, which no packet divides (`find_best_packet`,
// Eigen/src/Core/util/XprHelper.h): scalar code. Laid out across elements instead (structure
// of arrays: F(0, 0) of 8 elements side by side, then F(0, 1), ...), the same arithmetic
// fills every lane of a register (McAdams, Selle, Tamstorf, Teran & Sifakis 2011 compute
// their 3x3 SVD this way). The kernels are plain loops over the lanes with `#pragma omp
// simd`, which GCC and Clang turn into vector code for whatever -march=native offers (AVX2 or
// AVX-512) without intrinsics.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <vector>

#include "chapters/07_block_sparse/block_sparse.hpp"
#include "chapters/08_element_kernels/element_kernels.hpp"
#include "chapters/12_half_the_bytes/batch_rotations.hpp"
#include "common/model.hpp"

namespace fem::ch12 {

// What a batch of elements adds to the system, lane by lane: the terms of b (rhs[i][a]: row i,
// corner a) and the ten distinct blocks K[p][i][j] in ch08::kUpperPairs order.
struct BatchTerms {
  Lanes rhs[3][4];
  Lanes K[10][3][3];
};

struct GatheredBatch;  // a batch's numbers while terms() runs (element_batch.cpp)

// The element loop's state, as ch08::FusedElements's, across elements: the shapes and the last
// two steps' rotations, one array per component.
class BatchedElements {
 public:
  BatchedElements() = default;
  BatchedElements(const Model& model, const Scene& scene);

  // Elements first .. first + count - 1 (count <= kLanes) with corners tets[e]: lane l holds
  // element first + l, as ch08::FusedElements::terms computes it (rotation by Newton from the
  // predicted one; ch08::fast_polar_rotation's SVD where Newton cannot decide: ++fallbacks).
  // Writes only these elements' rotations: batches can be computed on any thread.
  void terms(int first, int count, const std::vector<Eigen::Vector4i>& tets, const State& state,
             long long& fallbacks, BatchTerms& out);
  // Once every element of the step is done: the next step extrapolates the rotations.
  void end_pass(long long fallbacks);

  Eigen::Quaterniond rotation(int e) const;  // of the last step (tests)
  long long last_step_fallbacks() const { return last_step_fallbacks_; }
  // In all steps so far: fallbacks, rotations computed, and Newton's iterations counted per
  // element as the lanes ran them (a batch's iterations times its elements).
  long long total_fallbacks() const { return total_fallbacks_; }
  long long total_rotations() const { return total_rotations_; }
  long long total_newton_iterations() const { return iterations_.total(); }

 private:
  void gather(int first, int count, const std::vector<Eigen::Vector4i>& tets, const State& state,
              GatheredBatch& g) const;
  void keep_rotations(int first, int count, const GatheredBatch& g, const Lanes (&q)[4]);

  int elements_ = 0;
  double h_ = 0.0, velocity_scale_ = 0.0, stiffness_ = 0.0;
  // Per element: Dm^-1 by entries (dm[3 * i + j]), V mu, V lambda, and the quaternions of the
  // last step and the step before (w, x, y, z), each component an array over the elements.
  std::array<std::vector<double>, 9> dm_;
  std::vector<double> mu_volume_, lambda_volume_;
  std::array<std::vector<double>, 4> rotation_, previous_;
  bool first_step_ = true;
  long long last_step_fallbacks_ = 0, total_fallbacks_ = 0, total_rotations_ = 0;
  ch08::IterationCounter iterations_;
};

// b += lane l's terms, A += its blocks (ten computed, sixteen written), at the element's blocks
// of the pattern: ch08::scatter for one lane.
void scatter(const BatchTerms& terms, int lane, const Eigen::Vector4i& t,
             const std::array<int, 16>& blocks, ch07::BlockSparseMatrix& A, Eigen::VectorXd& b);

}  // namespace fem::ch12
