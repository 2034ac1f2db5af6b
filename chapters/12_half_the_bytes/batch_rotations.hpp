// Chapter 12's rotations of a batch of elements, one element per lane: chapter 08's
// fast_polar_rotation (Newton from the predicted rotation; the SVD where Newton cannot decide)
// as loops over the lanes that the compiler turns into vector code.
#pragma once

namespace fem::ch12 {

// Elements per batch: 8 doubles fill an AVX-512 register, two AVX2 ones.
constexpr int kLanes = 8;

// One number per lane, aligned to a cache line.
struct alignas(64) Lanes {
  double v[kLanes];
};

// The polar rotations of F = Ds Dm^-1 (3x3 matrices by entries, [3 i + j]) as quaternions
// (w, x, y, z) in q, lane by lane as chapter 08 decides them: Newton from the predicted
// rotation last * conj(before) * last within ch08::newton's limits, chapter 08's
// fast_polar_rotation from the same start in lanes 0 .. count - 1 where Newton cannot decide
// (++fallbacks). The lanes past count need only hold valid numbers. Returns the Newton
// iterations the lanes ran together (every lane runs each one, in vector code).
int polar_rotations(const Lanes (&ds)[9], const Lanes (&dm)[9], const Lanes (&last)[4],
                    const Lanes (&before)[4], int count, Lanes (&q)[4], long long& fallbacks);

}  // namespace fem::ch12
