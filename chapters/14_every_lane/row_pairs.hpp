// Two block rows side by side, each in pair lanes (lanes.hpp): on AVX-512 one 512-bit register
// holds a pair of blocks of row i and a pair of row i + 1 (16 floats), so a row's products take
// half the instructions of the pair lanes alone. Rows are paired within each fixed row block
// (the partition every loop shares out), so a pair never straddles two threads' rows. The
// shorter row of a pair is padded with zero blocks: a zero product adds +0 or -0 to a sum that
// started at +0, which leaves its bits as they were (round to nearest never makes a sum -0
// from +0), so each row's sums stay the padded columns' to the bit. The padding costs its
// bytes: rows paired in chapter 11's order are mostly of the same length.
// (Row pairs are a SELL-C-sigma slice of C = 2 block rows, sigma = 1, Kreutzer, Hager,
// Wellein, Fehske and Bishop, SIAM J. Sci. Comput. 2014, each lane a pair of blocks.)
#pragma once

#include <Eigen/Core>
#include <vector>

#include "chapters/07_block_sparse/block_sparse.hpp"
#include "chapters/14_every_lane/fine_smoothing.hpp"
#include "chapters/14_every_lane/lanes.hpp"

namespace fem::ch14 {

// The lanes of two rows for any build: each row its own pair lanes.
struct GenericRowPairLanes {
  using Row = PairLanes<float>;
  struct Acc {
    Row::Acc row[2][3];
  };
  static Acc zero() {
    Acc acc;
    for (auto& row : acc.row)
      for (auto& column : row) column = Row::zero();
    return acc;
  }
  // One step: a pair of each row (48 floats at a: per column j, row 0's 8 then row 1's 8);
  // x: the four pieces (row 0 even, odd, row 1 even, odd), each read as 4 floats.
  static void add(Acc& acc, const float* a, const float* const (&x)[4]) {
    for (int r = 0; r < 2; ++r) {
      const Row::X pieces = Row::pair(x[2 * r], x[2 * r + 1]);
      Row::add_padded<0>(acc.row[r][0], a + 8 * r, pieces);
      Row::add_padded<1>(acc.row[r][1], a + 16 + 8 * r, pieces);
      Row::add_padded<2>(acc.row[r][2], a + 32 + 8 * r, pieces);
    }
  }
  static void totals(const Acc& acc, Eigen::Array4f& first, Eigen::Array4f& second) {
    first = Row::total(acc.row[0]);
    second = Row::total(acc.row[1]);
  }
};

#if defined(EIGEN_VECTORIZE_AVX512)
struct Avx512RowPairLanes {
  using Packet = Eigen::internal::Packet16f;
  struct Acc {
    Packet column[3];
  };
  static Acc zero() {
    const Packet z = Eigen::internal::pset1<Packet>(0.0f);
    return {{z, z, z}};
  }
  static Packet pieces(const float* const (&x)[4]) {
    using Eigen::internal::Packet4f;
    using Eigen::internal::ploadu;
    Packet p = _mm512_castps128_ps512(ploadu<Packet4f>(x[0]));
    p = _mm512_insertf32x4(p, ploadu<Packet4f>(x[1]), 1);
    p = _mm512_insertf32x4(p, ploadu<Packet4f>(x[2]), 2);
    return _mm512_insertf32x4(p, ploadu<Packet4f>(x[3]), 3);
  }
  static void add(Acc& acc, const float* a, const float* const (&x)[4]) {
    using Eigen::internal::padd;
    using Eigen::internal::pload;
    using Eigen::internal::pmul;
    const Packet X = pieces(x);
    acc.column[0] = padd(acc.column[0], pmul(pload<Packet>(a), _mm512_permute_ps(X, 0x00)));
    acc.column[1] = padd(acc.column[1], pmul(pload<Packet>(a + 16), _mm512_permute_ps(X, 0x55)));
    acc.column[2] = padd(acc.column[2], pmul(pload<Packet>(a + 32), _mm512_permute_ps(X, 0xAA)));
  }
  // Per row (c0 + c1) + c2 in each half, then even + odd: the padded columns' order.
  static void totals(const Acc& acc, Eigen::Array4f& first, Eigen::Array4f& second) {
    using Eigen::internal::padd;
    const Packet sum = padd(padd(acc.column[0], acc.column[1]), acc.column[2]);
    // lanes 4k..4k+3 + lanes of the neighbouring 128-bit piece: even + odd of each row
    const Packet both = padd(sum, _mm512_shuffle_f32x4(sum, sum, _MM_SHUFFLE(2, 3, 0, 1)));
    Eigen::internal::pstoreu(first.data(), _mm512_castps512_ps128(both));
    Eigen::internal::pstoreu(second.data(), _mm512_extractf32x4_ps(both, 2));
  }
};
using RowPairLanes = Avx512RowPairLanes;
#else
using RowPairLanes = GenericRowPairLanes;
#endif

// The float blocks of a 3x3 block matrix as row pairs within the fixed row blocks `part`.
class RowPairBlocks {
 public:
  static constexpr int kStep = 48;  // floats of one step: 3 columns of 2 rows x 8

  RowPairBlocks() = default;
  // The layout of `pattern`'s rows paired within the row blocks `part` (values zero).
  RowPairBlocks(const ch07::BlockCsr<3, 3>& pattern, const std::vector<int>& part);

  // The values of row pairs that start in [first, last) (rows of one or more whole parts).
  template <class Source>
  void fill(const Eigen::Matrix<Source, 3, 3>* values, int first, int last);

  // The sums of row i (paired with i + 1 in its part; i is the pair's first row) and of row
  // i + 1, over their blocks; second is zero if i has no partner.
  void row_products(int i, const float* x, Eigen::Array4f& first, Eigen::Array4f& second) const;

  // f(i, row i's sum) for every row i in [first, last) of whole row blocks, two at a time.
  template <class F>
  void for_rows(int first, int last, const float* x, F&& f) const {
    Eigen::Array4f sums[2];
    for (int i = first; i < last; ++i) {
      row_products(i, x, sums[0], sums[1]);
      f(i, sums[0]);
      if (has_partner(i)) f(++i, sums[1]);
    }
  }

  int rows() const { return static_cast<int>(row_start_.size()) - 1; }
  long long blocks() const { return row_start_.back(); }
  // Whether row i starts a pair with row i + 1 (else it is alone, or i + 1 starts the next).
  bool has_partner(int i) const { return i + 1 < rows() && group_[i + 1] < 0; }
  // What one pass over every row reads: values (padding included), x offsets, group tables.
  double bytes() const;

 private:
  std::vector<float, Eigen::aligned_allocator<float>> values_;
  std::vector<int> row_start_{0};   // the pattern's
  std::vector<int> group_;          // per row: its pair's index if it starts one, else -1
  std::vector<int> step_start_{0};  // per pair: its first step (kStep floats, 4 x offsets each)
  std::vector<int> x_offset_;       // per step: the 4 pieces' 3 * column (padding: node 0's)
  std::vector<char> at_end_;        // per step: whether its last piece is the last node's
  int last_x_offset_ = -1;
};

template <class Source>
void RowPairBlocks::fill(const Eigen::Matrix<Source, 3, 3>* values, int first, int last) {
  for (int i = first; i < last; ++i) {
    if (group_[i] < 0) continue;
    const int g = group_[i], steps = step_start_[g + 1] - step_start_[g];
    float* base = values_.data() + std::size_t(kStep) * step_start_[g];
    for (int r = 0; r < 2; ++r) {
      const int row = i + r;
      const bool real = r == 0 || has_partner(i);
      const int begin = real ? row_start_[row] : 0, count = real ? row_start_[row + 1] - begin : 0;
      for (int b = 0; b < 2 * steps; ++b) {
        // step b / 2, column j at 16 j, row r's 8 at 8 r, the odd block's 4 at 4
        float* a = base + kStep * (b / 2) + 8 * r + 4 * (b % 2);
        for (int j = 0; j < 3; ++j)
          for (int k = 0; k < 4; ++k)
            a[16 * j + k] = b < count && k < 3 ? static_cast<float>(values[begin + b](k, j)) : 0.0f;
      }
    }
  }
}

inline void RowPairBlocks::row_products(int i, const float* x, Eigen::Array4f& first,
                                        Eigen::Array4f& second) const {
  const int g = group_[i];
  auto acc = RowPairLanes::zero();
  const float* a = values_.data() + std::size_t(kStep) * step_start_[g];
  for (int s = step_start_[g]; s < step_start_[g + 1]; ++s, a += kStep) {
    const int* o = x_offset_.data() + 4 * s;
    if (!at_end_[s]) {
      const float* const pieces[4] = {x + o[0], x + o[1], x + o[2], x + o[3]};
      RowPairLanes::add(acc, a, pieces);
      continue;
    }
    // A piece of the last node: the four copied, so that nothing past x is read.
    alignas(16) float copy[4][4] = {};
    for (int p = 0; p < 4; ++p)
      for (int k = 0; k < 3; ++k) copy[p][k] = x[o[p] + k];
    const float* const pieces[4] = {copy[0], copy[1], copy[2], copy[3]};
    RowPairLanes::add(acc, a, pieces);
  }
  RowPairLanes::totals(acc, first, second);
}

// The row pairs as the V-cycle's finest level (fine_smoothing.hpp): the course measures it
// beside the step's pair lanes (lesson.cpp, apps/roofline/lanes_bench.cpp); no stepper runs it.
inline RowPairBlocks lanes_of(const ch10::Level<3>& level, const RowPairBlocks*) {
  return RowPairBlocks(level.A, level.rows.part);
}
using RowPairFineLevel = LaneLevel<RowPairBlocks>;

}  // namespace fem::ch14
