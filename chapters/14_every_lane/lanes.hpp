// The vector lanes of a pair of 3x3 blocks: two blocks of one block row side by side in one
// register, each block's column in 4 lanes (lanes 0-3 the row's even block, lanes 4-7 its odd
// one; the 4th lane of each a padding row, zero or a dropped product). A 3x3 block alone fills 3 of
// 4 lanes of a 128-bit register and leaves the rest of a 256- or 512-bit one idle; two blocks per
// register fill 8 lanes of float (256 bits) or of double (512 bits) with the same instructions. The
// x of the two blocks is loaded as two 4-scalar pieces and each column's entry is spread over its
// block's 4 lanes by an in-lane permute: no gather (slow on some cores: on the AMD EPYC this
// was measured on, issue 53's probe: three 16-lane gathers a slot, x0.8 of no lanes).
//
// The even and odd lanes keep apart the two partial sums that the scalar-per-block products
// keep (the even and the odd blocks of a row), and a sum per block column: the same
// multiply-adds in the same order per lane, so the float product is bit for bit the padded
// columns' one. Where Eigen has no such register (AVX for float, AVX-512 for double) the same
// lanes are two fixed-size Eigen arrays of 4: SSE2, NEON or scalar code, the same arithmetic.
// A lane's update is written as Eigen evaluates `sum += column * x` (an add of a multiply, not
// an explicit multiply-add), so that the compiler fuses it exactly where it fuses theirs.
#pragma once

#include <Eigen/Core>

namespace fem::ch14 {

// Two blocks in two arrays of 4 lanes, for any instruction set Eigen supports (or none).
template <class Scalar>
struct GenericPairLanes {
  using Half = Eigen::Array<Scalar, 4, 1>;
  struct Acc {
    Half even, odd;
  };
  struct X {  // the two blocks' x pieces, read lane by lane
    const Scalar *even, *odd;
  };

  static Acc zero() { return {Half::Zero(), Half::Zero()}; }
  static X pair(const Scalar* even, const Scalar* odd) { return {even, odd}; }
  static X pair_at_end(const Scalar* even, const Scalar* odd) { return {even, odd}; }
  // acc += the pair's column j times x's entries j: padded, 8 scalars at a (16-byte aligned,
  // each block's 4th row zero); packed, 6 at a (each block's 3, read as 4: the 4th lane
  // collects a harmless product of finite numbers, dropped).
  template <int j>
  static void add_padded(Acc& acc, const Scalar* a, const X& x) {
    acc.even += Eigen::Map<const Half, Eigen::Aligned16>(a) * x.even[j];
    acc.odd += Eigen::Map<const Half, Eigen::Aligned16>(a + 4) * x.odd[j];
  }
  template <int j>
  static void add_packed(Acc& acc, const Scalar* a, const X& x) {
    acc.even += Eigen::Map<const Half>(a) * x.even[j];
    acc.odd += Eigen::Map<const Half>(a + 3) * x.odd[j];
  }
  // The even lanes only, a column of 3 at a read as 4: a row's last block when it has an odd
  // count.
  template <int j>
  static void add_even(Acc& acc, const Scalar* a, const Scalar* x) {
    acc.even += Eigen::Map<const Half>(a) * x[j];
  }
  // (c0 + c1) + c2 in each half, then even + odd: the order of the padded columns' total.
  // Four lanes: the row's three sums and a dropped one.
  static Half total(const Acc (&acc)[3]) {
    return ((acc[0].even + acc[1].even) + acc[2].even) + ((acc[0].odd + acc[1].odd) + acc[2].odd);
  }
};

#if defined(EIGEN_VECTORIZE_AVX)
// Float on AVX (and AVX-512): a pair is one 256-bit register.
struct AvxFloatPairLanes {
  using Packet = Eigen::internal::Packet8f;
  using Acc = Packet;
  using X = Packet;

  static Acc zero() { return Eigen::internal::pset1<Packet>(0.0f); }
  // Reads one float past each piece (the next node's first): the caller keeps it in x.
  static X pair(const float* even, const float* odd) {
    using Eigen::internal::Packet4f;
    using Eigen::internal::ploadu;
    return _mm256_insertf128_ps(_mm256_castps128_ps256(ploadu<Packet4f>(even)),
                                ploadu<Packet4f>(odd), 1);
  }
  // The odd piece is x's last node: copied, so that nothing past x is read.
  static X pair_at_end(const float* even, const float* odd) {
    alignas(16) const float tail[4] = {odd[0], odd[1], odd[2], 0.0f};
    return pair(even, tail);
  }
  template <int j>
  static void add_padded(Acc& acc, const float* a, const X& x) {
    add_column<j>(acc, Eigen::internal::ploadu<Packet>(a), x);
  }
  // Packed: the two blocks' 3 floats joined from two loads of 4. (AVX-512's expanding load
  // would spread them without the join, but on the AMD EPYC measured it made the product
  // half as fast.)
  template <int j>
  static void add_packed(Acc& acc, const float* a, const X& x) {
    using Eigen::internal::Packet4f;
    using Eigen::internal::ploadu;
    add_column<j>(acc,
                  _mm256_insertf128_ps(_mm256_castps128_ps256(ploadu<Packet4f>(a)),
                                       ploadu<Packet4f>(a + 3), 1),
                  x);
  }
  template <int j>
  static void add_column(Acc& acc, const Packet& column, const X& x) {
    acc = Eigen::internal::padd(acc, Eigen::internal::pmul(column, _mm256_permute_ps(x, j * 0x55)));
  }
  template <int j>
  static void add_even(Acc& acc, const float* a, const float* x) {
    const Packet sum = Eigen::internal::padd(
        acc, Eigen::internal::pmul(
                 _mm256_castps128_ps256(Eigen::internal::ploadu<Eigen::internal::Packet4f>(a)),
                 Eigen::internal::pset1<Packet>(x[j])));
    acc = _mm256_blend_ps(acc, sum, 0x0F);  // the odd lanes keep their sums untouched
  }
  static Eigen::Array4f total(const Acc (&acc)[3]) {
    using Eigen::internal::padd;
    const Packet sum = padd(padd(acc[0], acc[1]), acc[2]);
    Eigen::Array4f out;
    Eigen::internal::pstoreu(out.data(),
                             padd(_mm256_castps256_ps128(sum), _mm256_extractf128_ps(sum, 1)));
    return out;
  }
};
template <class Scalar>
struct PairLanesOf {
  using type = GenericPairLanes<Scalar>;
};
template <>
struct PairLanesOf<float> {
  using type = AvxFloatPairLanes;
};
#else
template <class Scalar>
struct PairLanesOf {
  using type = GenericPairLanes<Scalar>;
};
#endif

#if defined(EIGEN_VECTORIZE_AVX512)
// Double on AVX-512: a pair is one 512-bit register (vpermpd permutes within 256-bit halves).
struct Avx512DoublePairLanes {
  using Packet = Eigen::internal::Packet8d;
  using Acc = Packet;
  using X = Packet;

  static Acc zero() { return Eigen::internal::pset1<Packet>(0.0); }
  static X pair(const double* even, const double* odd) {
    using Eigen::internal::Packet4d;
    using Eigen::internal::ploadu;
    return _mm512_insertf64x4(_mm512_castpd256_pd512(ploadu<Packet4d>(even)), ploadu<Packet4d>(odd),
                              1);
  }
  static X pair_at_end(const double* even, const double* odd) {
    alignas(32) const double tail[4] = {odd[0], odd[1], odd[2], 0.0};
    return pair(even, tail);
  }
  template <int j>
  static void add_padded(Acc& acc, const double* a, const X& x) {
    add_column<j>(acc, Eigen::internal::ploadu<Packet>(a), x);
  }
  template <int j>
  static void add_packed(Acc& acc, const double* a, const X& x) {
    using Eigen::internal::Packet4d;
    using Eigen::internal::ploadu;
    add_column<j>(
        acc,
        _mm512_insertf64x4(_mm512_castpd256_pd512(ploadu<Packet4d>(a)), ploadu<Packet4d>(a + 3), 1),
        x);
  }
  template <int j>
  static void add_column(Acc& acc, const Packet& column, const X& x) {
    acc =
        Eigen::internal::padd(acc, Eigen::internal::pmul(column, _mm512_permutex_pd(x, j * 0x55)));
  }
  template <int j>
  static void add_even(Acc& acc, const double* a, const double* x) {
    const Packet sum = Eigen::internal::padd(
        acc, Eigen::internal::pmul(
                 _mm512_castpd256_pd512(Eigen::internal::ploadu<Eigen::internal::Packet4d>(a)),
                 Eigen::internal::pset1<Packet>(x[j])));
    acc = _mm512_mask_blend_pd(0x0F, acc, sum);
  }
  static Eigen::Array4d total(const Acc (&acc)[3]) {
    using Eigen::internal::padd;
    const Packet sum = padd(padd(acc[0], acc[1]), acc[2]);
    Eigen::Array4d out;
    Eigen::internal::pstoreu(out.data(),
                             padd(_mm512_castpd512_pd256(sum), _mm512_extractf64x4_pd(sum, 1)));
    return out;
  }
};
template <>
struct PairLanesOf<double> {
  using type = Avx512DoublePairLanes;
};
#endif

// The lanes a pair of Scalar blocks takes on this build's instruction set.
template <class Scalar>
using PairLanes = typename PairLanesOf<Scalar>::type;

}  // namespace fem::ch14
