// Chapter 12's polar rotations of a batch (see batch_rotations.hpp): chapter 08's
// newton_polar_rotation for every lane at once, its branches as selects.
#include "chapters/12_half_the_bytes/batch_rotations.hpp"

#include <algorithm>
#include <cstdint>

#include "chapters/08_element_kernels/element_kernels.hpp"

namespace fem::ch12 {

namespace {

using namespace ch08::newton;

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

// Every loop runs over the lanes innermost, with no calls and no branches that selects cannot
// express: the square roots of chapter 08's tests become squared comparisons, since a call to
// sqrt may set errno and so stays scalar unless -fno-math-errno.

// Newton's start: F = Ds Dm^-1, whether Newton may decide, and its start
// last * conj(before) * last (ch08::predicted_rotation), quaternion products written out.
void newton_start(const Lanes (&ds)[9], const Lanes (&dm)[9], const Lanes (&last)[4],
                  const Lanes (&before)[4], Newton& n) {
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
    // det > k s^(3/2), squared: chapter 08's test (and false for NaN, as there). `&`, not
    // `&&`: a short circuit is control flow, which the vectorizer does not turn into selects.
    const bool decides =
        (det > 0.0) & (det * det > kMinRelativeDet * kMinRelativeDet * scale2 * scale2 * scale2);
    n.status[l] = decides ? kIterating : kFailed;
    const double aw = last[0].v[l], ax = last[1].v[l], ay = last[2].v[l], az = last[3].v[l];
    const double bw = before[0].v[l], bx = -before[1].v[l], by = -before[2].v[l],
                 bz = -before[3].v[l];
    const double cw = aw * bw - ax * bx - ay * by - az * bz,
                 cx = aw * bx + ax * bw + ay * bz - az * by,
                 cy = aw * by - ax * bz + ay * bw + az * bx,
                 cz = aw * bz + ax * by - ay * bx + az * bw;
    n.q[0].v[l] = n.start[0].v[l] = cw * aw - cx * ax - cy * ay - cz * az;
    n.q[1].v[l] = n.start[1].v[l] = cw * ax + cx * aw + cy * az - cz * ay;
    n.q[2].v[l] = n.start[2].v[l] = cw * ay - cx * az + cy * aw + cz * ax;
    n.q[3].v[l] = n.start[3].v[l] = cw * az + cx * ay - cy * ax + cz * aw;
  }
}

// Newton's step on every lane (chapter 08's newton_polar_rotation): R = R_q exp([w]) with
// H w = axial(A - A^T), A = R_q^T F; `definite` where chapter 08's solve_positive_definite
// would solve.
void newton_step(const Newton& n, Lanes (&step)[3], Flag (&definite)[kLanes]) {
  Lanes determinant;
#pragma omp simd
  for (int l = 0; l < kLanes; ++l) {
    const double w = n.q[0].v[l], x = n.q[1].v[l], y = n.q[2].v[l], z = n.q[3].v[l];
    // |q|^2 R(q / |q|), chapter 08's scaled_rotation.
    const double r0 = w * w + x * x - y * y - z * z, r1 = 2.0 * (x * y - w * z),
                 r2 = 2.0 * (x * z + w * y), r3 = 2.0 * (x * y + w * z),
                 r4 = w * w - x * x + y * y - z * z, r5 = 2.0 * (y * z - w * x),
                 r6 = 2.0 * (x * z - w * y), r7 = 2.0 * (y * z + w * x),
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
    const double q2 = w * w + x * x + y * y + z * z, s2 = n.scale2.v[l], q6 = q2 * q2 * q2;
    const double minor2 = H00 * H11 - H01 * H01;
    const double det = H00 * (H11 * H22 - H12 * H12) - H01 * (H01 * H22 - H12 * H02) +
                       H02 * (H01 * H12 - H11 * H02);
    // w = H^-1 axial by the adjugate: its numerators here, the division in a loop of its own.
    const double a0 = H11 * H22 - H12 * H12, a1 = H02 * H12 - H01 * H22, a2 = H01 * H12 - H02 * H11,
                 a4 = H00 * H22 - H02 * H02, a5 = H01 * H02 - H00 * H12;
    step[0].v[l] = a0 * b0 + a1 * b1 + a2 * b2;
    step[1].v[l] = a1 * b0 + a4 * b1 + a5 * b2;
    step[2].v[l] = a2 * b0 + a5 * b1 + minor2 * b2;
    determinant.v[l] = det;
    // det H > k q2^3 s2^(3/2), squared.
    definite[l] =
        (H00 > 0.0) & (minor2 > 0.0) & (det > 0.0) &
        (det * det > kMinRelativeHessianDet * kMinRelativeHessianDet * q6 * q6 * s2 * s2 * s2);
  }
  // Kept apart: with -ftrapping-math (GCC's default) a division that only some lanes use is
  // not executed for all of them, and the loop would stay scalar.
  for (int k = 0; k < 3; ++k) {
#pragma omp simd
    for (int l = 0; l < kLanes; ++l) step[k].v[l] /= determinant.v[l];
  }
}

// Newton's update: q * (1, w / 2) where the lane iterates and H was definite, and the lanes'
// new status. The update for every lane first, the selects in a loop of their own: with
// -ftrapping-math (GCC's default) the compiler sinks arithmetic used in one arm of a select
// into that arm, where an operation that may trap runs only for the lanes that asked for it,
// so the loop stays scalar on AVX2 (AVX-512 masks it). Loads, integer tests and selects have
// nothing to sink.
void newton_update(const Lanes (&step)[3], const Flag (&definite)[kLanes], Newton& n) {
  Lanes next_q[4];
  Flag converged[kLanes];
#pragma omp simd
  for (int l = 0; l < kLanes; ++l) {
    const double w = n.q[0].v[l], x = n.q[1].v[l], y = n.q[2].v[l], z = n.q[3].v[l];
    const double w0 = step[0].v[l], w1 = step[1].v[l], w2 = step[2].v[l];
    const double hx = 0.5 * w0, hy = 0.5 * w1, hz = 0.5 * w2;
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

// Phase 2: Newton on every lane still iterating, its branches as selects; a lane that
// converged or failed keeps its q. Returns the iterations run.
int newton_iterations(Newton& n) {
  Lanes step[3];
  Flag definite[kLanes];
  int it = 0;
  for (; it < kMaxIterations; ++it) {
    if (std::none_of(n.status, n.status + kLanes, [](Flag s) { return s == kIterating; })) break;
    newton_step(n, step, definite);
    newton_update(step, definite, n);
  }
  return it;
}

// Phase 3: the converged lanes normalized (chapter 08's q.normalize()), all lanes at once: the
// square root through Eigen's Array, whose sqrt is the vector instruction (psqrt,
// Eigen/src/Core/arch/AVX/PacketMath.h), where std::sqrt in a loop stays a call because it may
// set errno; the quotients first, the selects in a loop of their own (see newton_update).
// Then, one lane at a time, the lanes where Newton could not decide (or did not converge
// within the cap): chapter 08's path from the same start, which ends in the SVD.
void finish_rotations(int count, Newton& n, Lanes (&q)[4], long long& fallbacks) {
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
      q[c].v[l] = n.status[l] == kConverged ? unit[c].v[l] : n.q[c].v[l];
  }
  for (int l = 0; l < count; ++l) {
    if (n.status[l] == kConverged) continue;
    Eigen::Matrix3d F;
    for (int k = 0; k < 9; ++k) F(k / 3, k % 3) = n.F[k].v[l];
    Eigen::Quaterniond rotation(n.start[0].v[l], n.start[1].v[l], n.start[2].v[l], n.start[3].v[l]);
    ch08::fast_polar_rotation(F, rotation, fallbacks);
    const double c[4] = {rotation.w(), rotation.x(), rotation.y(), rotation.z()};
    for (int k = 0; k < 4; ++k) q[k].v[l] = c[k];
  }
}

}  // namespace

int polar_rotations(const Lanes (&ds)[9], const Lanes (&dm)[9], const Lanes (&last)[4],
                    const Lanes (&before)[4], int count, Lanes (&q)[4], long long& fallbacks) {
  Newton n;
  newton_start(ds, dm, last, before, n);
  const int iterations = newton_iterations(n);
  finish_rotations(count, n, q, fallbacks);
  return iterations;
}

}  // namespace fem::ch12
