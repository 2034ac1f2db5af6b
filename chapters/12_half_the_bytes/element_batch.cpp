// Chapter 12's element pass across elements (see element_batch.hpp): chapter 08's arithmetic
// (element_kernels.cpp) in four phases per batch, each a loop over the lanes that the compiler
// vectorizes: the gather of the corners, F and Newton's start; Newton's iterations, every lane
// at once until all have converged or failed; the SVD for the lanes that failed, one at a time
// (chapter 08's fast_polar_rotation); and the rotated gradients, forces and blocks.
#include "chapters/12_half_the_bytes/element_batch.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace fem::ch12 {

namespace {

// Chapter 08's constants (element_kernels.cpp): the same decisions element by element.
constexpr double kMinRelativeDet = 1e-4;
constexpr double kConvergedStep = 1e-8;
constexpr int kMaxIterations = 12;

// A lane's flags as wide as its doubles, so that a select on a flag picks between doubles
// lane for lane.
using Flag = std::int64_t;
enum : Flag { kIterating = 0, kConverged = 1, kFailed = -1 };

// A batch's rotations while Newton runs: the iterate q and Newton's start (kept for the lanes
// that fall back), F, |F|^2 / 3, and each lane's status.
struct Newton {
  Lanes q[4], start[4], F[9], scale2;
  Flag status[kLanes];
};

// A batch's lanes as an Eigen array, for the operations a plain loop cannot vectorize.
using LaneArray = Eigen::Map<Eigen::Array<double, kLanes, 1>, Eigen::Aligned64>;

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
  // Phase 1, the gather. The element's own numbers are arrays over the elements already: a
  // full batch copies kLanes consecutive entries of each (vector loads). The corners are
  // indexed loads, one node's x and v per corner and lane. A short batch (the end of a
  // colour group) repeats its last element in the lanes past `count`: valid numbers, whose
  // results are never written.
  Lanes ds[9], dv[9], dm[9], last[4], before[4], mu, lambda;
  int lane_element[kLanes];
  for (int l = 0; l < kLanes; ++l) lane_element[l] = first + std::min(l, count - 1);
  if (count == kLanes) {
    copy_lanes(dm_, first, dm);
    copy_lanes(rotation_, first, last);
    copy_lanes(previous_, first, before);
    copy_lanes(mu_volume_, first, mu);
    copy_lanes(lambda_volume_, first, lambda);
  } else {
    for (int l = 0; l < kLanes; ++l) {
      const int e = lane_element[l];
      for (int k = 0; k < 9; ++k) dm[k].v[l] = dm_[k][e];
      for (int c = 0; c < 4; ++c) {
        last[c].v[l] = rotation_[c][e];
        before[c].v[l] = previous_[c][e];
      }
      mu.v[l] = mu_volume_[e];
      lambda.v[l] = lambda_volume_[e];
    }
  }
  const double* x = state.x.data();
  const double* v = state.v.data();
  for (int l = 0; l < kLanes; ++l) {
    const Eigen::Vector4i& t = tets[lane_element[l]];
    for (int i = 0; i < 3; ++i) {
      const double x0 = x[3 * t[0] + i], v0 = v[3 * t[0] + i];
      for (int j = 0; j < 3; ++j) {
        ds[3 * i + j].v[l] = x[3 * t[j + 1] + i] - x0;
        dv[3 * i + j].v[l] = v[3 * t[j + 1] + i] - v0;
      }
    }
  }
  // From here on every loop runs over the lanes innermost, on arrays of Lanes: the form that
  // compilers vectorize without being asked twice (no calls, no branches that selects cannot
  // express; the square roots of chapter 08's tests become squared comparisons, since a call
  // to sqrt may set errno and so stays scalar unless -fno-math-errno).
  Newton n;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
#pragma omp simd
      for (int l = 0; l < kLanes; ++l)
        n.F[3 * i + j].v[l] = ds[3 * i + 0].v[l] * dm[0 + j].v[l] +
                              ds[3 * i + 1].v[l] * dm[3 + j].v[l] +
                              ds[3 * i + 2].v[l] * dm[6 + j].v[l];
    }
#pragma omp simd
  for (int l = 0; l < kLanes; ++l) {
    const double f0 = n.F[0].v[l], f1 = n.F[1].v[l], f2 = n.F[2].v[l], f3 = n.F[3].v[l],
                 f4 = n.F[4].v[l], f5 = n.F[5].v[l], f6 = n.F[6].v[l], f7 = n.F[7].v[l],
                 f8 = n.F[8].v[l];
    const double norm2 =
        f0 * f0 + f1 * f1 + f2 * f2 + f3 * f3 + f4 * f4 + f5 * f5 + f6 * f6 + f7 * f7 + f8 * f8;
    const double det =
        f0 * (f4 * f8 - f5 * f7) - f1 * (f3 * f8 - f5 * f6) + f2 * (f3 * f7 - f4 * f6);
    const double scale2 = norm2 / 3.0;
    n.scale2.v[l] = scale2;
    // det > k s^(3/2), squared: chapter 08's test (and false for NaN, as there).
    // `&`, not `&&`: both sides evaluated, so no branch (a short circuit is control flow,
    // which the vectorizer does not turn into selects).
    const bool decides =
        (det > 0.0) & (det * det > kMinRelativeDet * kMinRelativeDet * scale2 * scale2 * scale2);
    n.status[l] = decides ? kIterating : kFailed;
    // Newton's start, last * conj(before) * last: quaternion products written out (w, x, y, z).
    const double aw = last[0].v[l], ax = last[1].v[l], ay = last[2].v[l], az = last[3].v[l];
    const double bw = before[0].v[l], bx = -before[1].v[l], by = -before[2].v[l],
                 bz = -before[3].v[l];
    const double cw = aw * bw - ax * bx - ay * by - az * bz,
                 cx = aw * bx + ax * bw + ay * bz - az * by,
                 cy = aw * by - ax * bz + ay * bw + az * bx,
                 cz = aw * bz + ax * by - ay * bx + az * bw;
    const double qw = cw * aw - cx * ax - cy * ay - cz * az,
                 qx = cw * ax + cx * aw + cy * az - cz * ay,
                 qy = cw * ay - cx * az + cy * aw + cz * ax,
                 qz = cw * az + cx * ay - cy * ax + cz * aw;
    n.q[0].v[l] = n.start[0].v[l] = qw;
    n.q[1].v[l] = n.start[1].v[l] = qx;
    n.q[2].v[l] = n.start[2].v[l] = qy;
    n.q[3].v[l] = n.start[3].v[l] = qz;
  }

  // Phase 2, Newton on every lane still iterating (chapter 08's newton_polar_rotation, its
  // branches as selects): R = R_q exp([w]) with H w = axial(A - A^T), A = R_q^T F. A lane that
  // converged or failed keeps its q; the converged ones are normalized after the loop.
  Lanes step[3], determinant;
  Flag definite[kLanes];
  for (int it = 0; it < kMaxIterations; ++it) {
    if (std::none_of(n.status, n.status + kLanes, [](Flag s) { return s == kIterating; })) break;
#pragma omp simd
    for (int l = 0; l < kLanes; ++l) {
      const double w = n.q[0].v[l], x = n.q[1].v[l], y = n.q[2].v[l], z = n.q[3].v[l];
      // |q|^2 R(q / |q|), chapter 08's scaled_rotation.
      const double r0 = w * w + x * x - y * y - z * z, r1 = 2.0 * (x * y - w * z),
                   r2 = 2.0 * (x * z + w * y);
      const double r3 = 2.0 * (x * y + w * z), r4 = w * w - x * x + y * y - z * z,
                   r5 = 2.0 * (y * z - w * x);
      const double r6 = 2.0 * (x * z - w * y), r7 = 2.0 * (y * z + w * x),
                   r8 = w * w - x * x - y * y + z * z;
      const double f0 = n.F[0].v[l], f1 = n.F[1].v[l], f2 = n.F[2].v[l], f3 = n.F[3].v[l],
                   f4 = n.F[4].v[l], f5 = n.F[5].v[l], f6 = n.F[6].v[l], f7 = n.F[7].v[l],
                   f8 = n.F[8].v[l];
      // A = R^T F: A(i, j) = sum_k R(k, i) F(k, j).
      const double A0 = r0 * f0 + r3 * f3 + r6 * f6, A1 = r0 * f1 + r3 * f4 + r6 * f7,
                   A2 = r0 * f2 + r3 * f5 + r6 * f8, A3 = r1 * f0 + r4 * f3 + r7 * f6,
                   A4 = r1 * f1 + r4 * f4 + r7 * f7, A5 = r1 * f2 + r4 * f5 + r7 * f8,
                   A6 = r2 * f0 + r5 * f3 + r8 * f6, A7 = r2 * f1 + r5 * f4 + r8 * f7,
                   A8 = r2 * f2 + r5 * f5 + r8 * f8;
      const double b0 = A7 - A5, b1 = A2 - A6, b2 = A3 - A1;  // axial(A - A^T)
      const double trace = A0 + A4 + A8;
      const double H00 = trace - A0, H11 = trace - A4, H22 = trace - A8;
      const double H01 = -0.5 * (A1 + A3), H02 = -0.5 * (A2 + A6), H12 = -0.5 * (A5 + A7);
      const double q2 = w * w + x * x + y * y + z * z, s2 = n.scale2.v[l];
      const double minor2 = H00 * H11 - H01 * H01;
      const double det = H00 * (H11 * H22 - H12 * H12) - H01 * (H01 * H22 - H12 * H02) +
                         H02 * (H01 * H12 - H11 * H02);
      // det H > 1e-12 q2^3 s2^(3/2), squared (chapter 08's solve_positive_definite).
      const double q6 = q2 * q2 * q2;
      // w = H^-1 axial by the adjugate: its numerators here, the division in a loop of its own.
      const double a0 = H11 * H22 - H12 * H12, a1 = H02 * H12 - H01 * H22,
                   a2 = H01 * H12 - H02 * H11;
      const double a4 = H00 * H22 - H02 * H02, a5 = H01 * H02 - H00 * H12;
      step[0].v[l] = a0 * b0 + a1 * b1 + a2 * b2;
      step[1].v[l] = a1 * b0 + a4 * b1 + a5 * b2;
      step[2].v[l] = a2 * b0 + a5 * b1 + minor2 * b2;
      determinant.v[l] = det;
      definite[l] =
          (H00 > 0.0) & (minor2 > 0.0) & (det > 0.0) & (det * det > 1e-24 * q6 * q6 * s2 * s2 * s2);
    }
    // Kept apart: with -ftrapping-math (GCC's default) a division that only some lanes use is
    // not executed for all of them, and the loop would stay scalar.
    for (int k = 0; k < 3; ++k) {
#pragma omp simd
      for (int l = 0; l < kLanes; ++l) step[k].v[l] /= determinant.v[l];
    }
    // The Newton update for every lane, then the selects in a loop of their own: with
    // -ftrapping-math (GCC's default) the compiler sinks arithmetic used in one arm of a select
    // into that arm, and a floating-point operation that may trap is not executed for lanes
    // that did not ask for it, so the loop stays scalar on AVX2 ("control flow in loop";
    // AVX-512 masks the operation instead). A loop of loads, integer tests and selects has
    // nothing to sink.
    Lanes next_q[4];
    Flag converged[kLanes];
#pragma omp simd
    for (int l = 0; l < kLanes; ++l) {
      const double w = n.q[0].v[l], x = n.q[1].v[l], y = n.q[2].v[l], z = n.q[3].v[l];
      const double w0 = step[0].v[l], w1 = step[1].v[l], w2 = step[2].v[l];
      const double hx = 0.5 * w0, hy = 0.5 * w1, hz = 0.5 * w2;  // q * (1, w / 2)
      next_q[0].v[l] = w - x * hx - y * hy - z * hz;
      next_q[1].v[l] = x + w * hx + y * hz - z * hy;
      next_q[2].v[l] = y + w * hy - x * hz + z * hx;
      next_q[3].v[l] = z + w * hz + x * hy - y * hx;
      converged[l] = w0 * w0 + w1 * w1 + w2 * w2 < kConvergedStep * kConvergedStep;
    }
#pragma omp simd
    for (int l = 0; l < kLanes; ++l) {
      const Flag status = n.status[l];
      const Flag iterating = status == kIterating;
      const Flag update = iterating & definite[l];
      for (int c = 0; c < 4; ++c) n.q[c].v[l] = update ? next_q[c].v[l] : n.q[c].v[l];
      // definite ? (converged ? kConverged : kIterating) : kFailed, as arithmetic: a nested
      // select would evaluate `converged` in one arm only, a branch again.
      static_assert(kFailed == -1 && kIterating == 0 && kConverged == 1, "the states' values");
      const Flag next = definite[l] * (1 + converged[l]) - 1;
      n.status[l] = status + iterating * (next - status);
    }
  }

  // Phase 3: the converged lanes normalized (chapter 08's q.normalize()), for all lanes at
  // once: the square root through Eigen's Array, whose sqrt is the vector instruction
  // (psqrt, Eigen/src/Core/arch/AVX/PacketMath.h), where std::sqrt in a loop stays a call
  // because it may set errno; the quotients first, the selects in a loop of their own (see
  // phase 2). Then, one lane at a time, the lanes where Newton could not decide (or did not
  // converge within the cap): chapter 08's path from the same start, which ends in the SVD.
  Lanes norm, unit[4];
#pragma omp simd
  for (int l = 0; l < kLanes; ++l)
    norm.v[l] = n.q[0].v[l] * n.q[0].v[l] + n.q[1].v[l] * n.q[1].v[l] + n.q[2].v[l] * n.q[2].v[l] +
                n.q[3].v[l] * n.q[3].v[l];
  LaneArray(norm.v) = LaneArray(norm.v).sqrt();
  for (int c = 0; c < 4; ++c) {
#pragma omp simd
    for (int l = 0; l < kLanes; ++l) unit[c].v[l] = n.q[c].v[l] / norm.v[l];
  }
  for (int c = 0; c < 4; ++c) {
#pragma omp simd
    for (int l = 0; l < kLanes; ++l)
      n.q[c].v[l] = n.status[l] == kConverged ? unit[c].v[l] : n.q[c].v[l];
  }
  for (int l = 0; l < count; ++l) {
    if (n.status[l] == kConverged) continue;
    Eigen::Matrix3d F;
    for (int k = 0; k < 9; ++k) F(k / 3, k % 3) = n.F[k].v[l];
    Eigen::Quaterniond q(n.start[0].v[l], n.start[1].v[l], n.start[2].v[l], n.start[3].v[l]);
    ch08::fast_polar_rotation(F, q, fallbacks);
    const double c[4] = {q.w(), q.x(), q.y(), q.z()};
    for (int k = 0; k < 4; ++k) n.q[k].v[l] = c[k];
  }
  // The next step's start, as chapter 08 keeps it: this step's rotation and the last one.
  for (int c = 0; c < 4; ++c) {
    double* previous = previous_[c].data() + first;
    double* rotation = rotation_[c].data() + first;
    if (count == kLanes) {
#pragma omp simd
      for (int l = 0; l < kLanes; ++l) {
        previous[l] = first_step_ ? n.q[c].v[l] : last[c].v[l];
        rotation[l] = n.q[c].v[l];
      }
    } else {
      for (int l = 0; l < count; ++l) {
        previous[l] = first_step_ ? n.q[c].v[l] : last[c].v[l];
        rotation[l] = n.q[c].v[l];
      }
    }
  }

  // Phase 4, chapter 08's terms: R (Eigen's Quaternion::toRotationMatrix, as chapter 08 calls
  // it), r = R [g_0 .. g_3], G = (Ds + (h + beta) Dv) [r_1 r_2 r_3]^T, the linear stress P,
  // b's terms -h P r, and the blocks of (h beta + h^2) K.
  Lanes R[9], r[3][4], E[9], P[3][3], smu, slambda;
#pragma omp simd
  for (int l = 0; l < kLanes; ++l) {
    const double w = n.q[0].v[l], x = n.q[1].v[l], y = n.q[2].v[l], z = n.q[3].v[l];
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
    smu.v[l] = stiffness_ * mu.v[l];
    slambda.v[l] = stiffness_ * lambda.v[l];
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
  for (int k = 0; k < 9; ++k) {
#pragma omp simd
    for (int l = 0; l < kLanes; ++l) E[k].v[l] = ds[k].v[l] + velocity_scale_ * dv[k].v[l];
  }
  Lanes G[3][3];
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
            lambda.v[l] * (G[0][0].v[l] + G[1][1].v[l] + G[2][2].v[l] - 3.0) - 2.0 * mu.v[l];
        P[i][j].v[l] = -h_ * (mu.v[l] * (G[i][j].v[l] + G[j][i].v[l]) + (i == j ? diagonal : 0.0));
      }
    }
  for (int i = 0; i < 3; ++i)
    for (int a = 0; a < 4; ++a) {
#pragma omp simd
      for (int l = 0; l < kLanes; ++l)
        out.rhs[i][a].v[l] =
            P[i][0].v[l] * r[0][a].v[l] + P[i][1].v[l] * r[1][a].v[l] + P[i][2].v[l] * r[2][a].v[l];
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

void BatchedElements::end_pass(long long fallbacks) {
  first_step_ = false;
  last_step_fallbacks_ = fallbacks;
}

Eigen::Quaterniond BatchedElements::rotation(int e) const {
  return Eigen::Quaterniond(rotation_[0][e], rotation_[1][e], rotation_[2][e], rotation_[3][e]);
}

void scatter(const BatchTerms& terms, int lane, const Eigen::Vector4i& t,
             const std::array<int, 16>& blocks, ch07::BlockSparseMatrix& A, Eigen::VectorXd& b) {
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
