// Chapter 12's element pass across elements (see element_batch.hpp): chapter 08's arithmetic
// (element_kernels.cpp) in four phases per batch (BatchedElements::terms): the gather; Newton's
// rotations, every lane at once until all have converged or failed; the SVD for the lanes that
// failed, one at a time (those two in batch_rotations.cpp); the rotated gradients, forces and
// blocks. Every loop runs over the lanes innermost, on arrays of Lanes: the form compilers
// vectorize without being asked twice (no calls, no branches that selects cannot express).
#include "chapters/12_half_the_bytes/element_batch.hpp"

#include <algorithm>

namespace fem::ch12 {

// A batch's numbers, lane by lane: Ds and Dv (corners 1-3 minus corner 0, by entries), Dm^-1,
// the rotations of the last step and the step before (w, x, y, z), V mu and V lambda.
struct GatheredBatch {
  Lanes ds[9], dv[9], dm[9], last[4], before[4], mu, lambda;
};

namespace {

// to[k].v = from[k][first .. first + kLanes - 1], for each of N arrays over the elements.
template <std::size_t N>
void copy_lanes(const std::array<std::vector<double>, N>& from, int first, Lanes* to) {
  for (std::size_t k = 0; k < N; ++k) {
    const double* in = from[k].data() + first;
#pragma omp simd
    for (int l = 0; l < kLanes; ++l) to[k].v[l] = in[l];
  }
}

void copy_lanes(const std::vector<double>& from, int first, Lanes& to) {
  const double* in = from.data() + first;
#pragma omp simd
  for (int l = 0; l < kLanes; ++l) to.v[l] = in[l];
}

// Phase 4, its start: R of each lane's q (Eigen's Quaternion::toRotationMatrix, as chapter 08
// calls it) and the rotated gradients r = R [g_0 .. g_3].
void rotated_gradients(const Lanes (&q)[4], const Lanes (&dm)[9], Lanes (&r)[3][4]) {
  Lanes R[9];
#pragma omp simd
  for (int l = 0; l < kLanes; ++l) {
    const double w = q[0].v[l], x = q[1].v[l], y = q[2].v[l], z = q[3].v[l];
    const double tx = 2 * x, ty = 2 * y, tz = 2 * z;
    const double twx = tx * w, twy = ty * w, twz = tz * w, txx = tx * x, txy = ty * x, txz = tz * x;
    const double tyy = ty * y, tyz = tz * y, tzz = tz * z;
    R[0].v[l] = 1 - (tyy + tzz);
    R[1].v[l] = txy - twz;
    R[2].v[l] = txz + twy;
    R[3].v[l] = txy + twz;
    R[4].v[l] = 1 - (txx + tzz);
    R[5].v[l] = tyz - twx;
    R[6].v[l] = txz - twy;
    R[7].v[l] = tyz + twx;
    R[8].v[l] = 1 - (txx + tyy);
  }
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
#pragma omp simd
      for (int l = 0; l < kLanes; ++l)
        r[i][j + 1].v[l] = R[3 * i + 0].v[l] * dm[3 * j + 0].v[l] +
                           R[3 * i + 1].v[l] * dm[3 * j + 1].v[l] +
                           R[3 * i + 2].v[l] * dm[3 * j + 2].v[l];
    }
#pragma omp simd
    for (int l = 0; l < kLanes; ++l) r[i][0].v[l] = -(r[i][1].v[l] + r[i][2].v[l] + r[i][3].v[l]);
  }
}

// Phase 4, b's terms: G = (Ds + (h + beta) Dv) [r_1 r_2 r_3]^T, the linear stress P, -h P r.
void forces(const GatheredBatch& g, const Lanes (&r)[3][4], double h, double velocity_scale,
            BatchTerms& out) {
  Lanes E[9], G[3][3], P[3][3];
  for (int k = 0; k < 9; ++k) {
#pragma omp simd
    for (int l = 0; l < kLanes; ++l) E[k].v[l] = g.ds[k].v[l] + velocity_scale * g.dv[k].v[l];
  }
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
#pragma omp simd
      for (int l = 0; l < kLanes; ++l)
        G[i][j].v[l] = E[3 * i + 0].v[l] * r[j][1].v[l] + E[3 * i + 1].v[l] * r[j][2].v[l] +
                       E[3 * i + 2].v[l] * r[j][3].v[l];
    }
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
#pragma omp simd
      for (int l = 0; l < kLanes; ++l) {
        const double diagonal =
            g.lambda.v[l] * (G[0][0].v[l] + G[1][1].v[l] + G[2][2].v[l] - 3.0) - 2.0 * g.mu.v[l];
        P[i][j].v[l] = -h * (g.mu.v[l] * (G[i][j].v[l] + G[j][i].v[l]) + (i == j ? diagonal : 0.0));
      }
    }
  for (int i = 0; i < 3; ++i)
    for (int a = 0; a < 4; ++a) {
#pragma omp simd
      for (int l = 0; l < kLanes; ++l)
        out.rhs[i][a].v[l] =
            P[i][0].v[l] * r[0][a].v[l] + P[i][1].v[l] * r[1][a].v[l] + P[i][2].v[l] * r[2][a].v[l];
    }
}

// Phase 4, A's terms: the blocks of (h beta + h^2) K, ch08::stiffness_blocks lane by lane.
void blocks(const GatheredBatch& g, const Lanes (&r)[3][4], double stiffness, BatchTerms& out) {
  Lanes smu, slambda;
#pragma omp simd
  for (int l = 0; l < kLanes; ++l) {
    smu.v[l] = stiffness * g.mu.v[l];
    slambda.v[l] = stiffness * g.lambda.v[l];
  }
  for (int p = 0; p < 10; ++p) {
    const int a = ch08::kUpperPairs[p][0], b = ch08::kUpperPairs[p][1];
    Lanes dot;
#pragma omp simd
    for (int l = 0; l < kLanes; ++l)
      dot.v[l] =
          r[0][a].v[l] * r[0][b].v[l] + r[1][a].v[l] * r[1][b].v[l] + r[2][a].v[l] * r[2][b].v[l];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
#pragma omp simd
        for (int l = 0; l < kLanes; ++l)
          out.K[p][i][j].v[l] = smu.v[l] * (r[i][b].v[l] * r[j][a].v[l]) +
                                slambda.v[l] * (r[j][b].v[l] * r[i][a].v[l]) +
                                (i == j ? smu.v[l] * dot.v[l] : 0.0);
      }
  }
}

}  // namespace

BatchedElements::BatchedElements(const Model& model, const Scene& scene)
    : elements_(static_cast<int>(model.tets.size())),
      h_(scene.dt),
      velocity_scale_(scene.dt + scene.damping.beta),
      stiffness_(scene.dt * scene.damping.beta + scene.dt * scene.dt) {
  const Lame lame =
      lame_from_young_poisson(scene.material.youngs_modulus, scene.material.poisson_ratio);
  for (auto& d : dm_) d.resize(elements_);
  mu_volume_.resize(elements_);
  lambda_volume_.resize(elements_);
  for (int e = 0; e < elements_; ++e) {
    const ch08::ElementShape shape = ch08::make_element_shape(model.rest[e], lame);
    for (int k = 0; k < 9; ++k) dm_[k][e] = shape.Dm_inv(k / 3, k % 3);
    mu_volume_[e] = shape.mu_volume;
    lambda_volume_[e] = shape.lambda_volume;
  }
  // The rest shape's rotation, as chapter 08 starts.
  for (int c = 0; c < 4; ++c) rotation_[c].assign(elements_, c == 0 ? 1.0 : 0.0);
  previous_ = rotation_;
}

void BatchedElements::terms(int first, int count, const std::vector<Eigen::Vector4i>& tets,
                            const State& state, long long& fallbacks, BatchTerms& out) {
  GatheredBatch g;
  gather(first, count, tets, state, g);
  Lanes q[4], r[3][4];
  iterations_.add(
      static_cast<long long>(polar_rotations(g.ds, g.dm, g.last, g.before, count, q, fallbacks)) *
      count);
  keep_rotations(first, count, g, q);
  rotated_gradients(q, g.dm, r);
  forces(g, r, h_, velocity_scale_, out);
  blocks(g, r, stiffness_, out);
}

// Phase 1, the gather. The element's own numbers are arrays over the elements already: a full
// batch copies kLanes consecutive entries of each (vector loads). The corners are indexed
// loads, one node's x and v per corner and lane. A short batch (the end of a colour group)
// repeats its last element in the lanes past `count`: valid numbers, whose results are never
// written.
void BatchedElements::gather(int first, int count, const std::vector<Eigen::Vector4i>& tets,
                             const State& state, GatheredBatch& g) const {
  int lane_element[kLanes];
  for (int l = 0; l < kLanes; ++l) lane_element[l] = first + std::min(l, count - 1);
  if (count == kLanes) {
    copy_lanes(dm_, first, g.dm);
    copy_lanes(rotation_, first, g.last);
    copy_lanes(previous_, first, g.before);
    copy_lanes(mu_volume_, first, g.mu);
    copy_lanes(lambda_volume_, first, g.lambda);
  } else {
    for (int l = 0; l < kLanes; ++l) {
      const int e = lane_element[l];
      for (int k = 0; k < 9; ++k) g.dm[k].v[l] = dm_[k][e];
      for (int c = 0; c < 4; ++c) {
        g.last[c].v[l] = rotation_[c][e];
        g.before[c].v[l] = previous_[c][e];
      }
      g.mu.v[l] = mu_volume_[e];
      g.lambda.v[l] = lambda_volume_[e];
    }
  }
  const double* x = state.x.data();
  const double* v = state.v.data();
  for (int l = 0; l < kLanes; ++l) {
    const Eigen::Vector4i& t = tets[lane_element[l]];
    for (int i = 0; i < 3; ++i) {
      const double x0 = x[3 * t[0] + i], v0 = v[3 * t[0] + i];
      for (int j = 0; j < 3; ++j) {
        g.ds[3 * i + j].v[l] = x[3 * t[j + 1] + i] - x0;
        g.dv[3 * i + j].v[l] = v[3 * t[j + 1] + i] - v0;
      }
    }
  }
}

// The next step's start, as chapter 08 keeps it: this step's rotation and the last one.
void BatchedElements::keep_rotations(int first, int count, const GatheredBatch& g,
                                     const Lanes (&q)[4]) {
  for (int c = 0; c < 4; ++c) {
    double* previous = previous_[c].data() + first;
    double* rotation = rotation_[c].data() + first;
    if (count == kLanes) {
#pragma omp simd
      for (int l = 0; l < kLanes; ++l) {
        previous[l] = first_step_ ? q[c].v[l] : g.last[c].v[l];
        rotation[l] = q[c].v[l];
      }
    } else {
      for (int l = 0; l < count; ++l) {
        previous[l] = first_step_ ? q[c].v[l] : g.last[c].v[l];
        rotation[l] = q[c].v[l];
      }
    }
  }
}

void BatchedElements::end_pass(long long fallbacks) {
  first_step_ = false;
  last_step_fallbacks_ = fallbacks;
  total_fallbacks_ += fallbacks;
  total_rotations_ += elements_;
}

Eigen::Quaterniond BatchedElements::rotation(int e) const {
  return Eigen::Quaterniond(rotation_[0][e], rotation_[1][e], rotation_[2][e], rotation_[3][e]);
}

void scatter(const BatchTerms& terms, int lane, const Eigen::Vector4i& t,
             const std::array<int, 16>& blocks, ch07::BlockSparseMatrix& A, Eigen::VectorXd& b) {
  // Straight from the lanes, not through chapter 08's ElementTerms: a copy of 102 doubles per
  // element would cost the pass (`fem_lessons batched-elements`, the scatter columns).
  for (int a = 0; a < 4; ++a)
    for (int i = 0; i < 3; ++i) b[3 * t[a] + i] += terms.rhs[i][a].v[lane];
  for (std::size_t p = 0; p < ch08::kUpperPairs.size(); ++p) {
    const int a = ch08::kUpperPairs[p][0], c = ch08::kUpperPairs[p][1];
    Eigen::Matrix3d K;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) K(i, j) = terms.K[p][i][j].v[lane];
    A.blocks[blocks[4 * a + c]] += K;
    if (a != c) A.blocks[blocks[4 * c + a]] += K.transpose();
  }
}

}  // namespace fem::ch12
