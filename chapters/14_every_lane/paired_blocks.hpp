// A block compressed row matrix of 3x3 blocks stored for the pair lanes (lanes.hpp): each
// block row's blocks taken two at a time from its first, a pair stored as its three columns,
// each column as the two blocks' columns side by side; an odd row's last block alone after
// its pairs. Two layouts: padded, each column 4 scalars (the 4th zero), a pair's column one
// whole-register load; packed, 3 (the block's own 36 bytes of float, 72 of double), a pair's
// column joined from two loads of 4 (the 4th lane a harmless product, dropped). Which is
// faster depends on what holds the kernel: on the AMD EPYC measured, the fine float level,
// held in the core, is faster padded; the double product, held by its bytes, packed. A row
// starts at kBlock times its first block's index: the products are found from the block
// range [begin, end) alone, as the V-cycle's row_product is called, without a table of rows.
//
// The pattern and the layout are set up once; the values are copied in by rows (fill), every
// step on the finest level, from the double blocks (a float copy rounds them as a cast does).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "chapters/07_block_sparse/block_sparse.hpp"
#include "chapters/14_every_lane/lanes.hpp"

namespace fem::ch14 {

template <class Scalar, bool Packed>
class PairedBlocks {
 public:
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
  using Sum4 = Eigen::Array<Scalar, 4, 1>;
  // Scalars a block: 3 columns of 3 (packed) or of 4 (padded); in a pair, one column of
  // both blocks every kColumn scalars, the odd block's kOdd on.
  static constexpr int kBlock = Packed ? 9 : 12;
  static constexpr int kColumn = Packed ? 6 : 8, kOdd = Packed ? 3 : 4;

  PairedBlocks() = default;
  // The layout of `pattern`'s blocks (values zero).
  explicit PairedBlocks(const ch07::BlockCsr<3, 3>& pattern);

  // The values of rows [first, last) from `values` (indexed as the pattern's blocks).
  template <class Source>
  void fill(const Eigen::Matrix<Source, 3, 3>* values, int first, int last);

  // sum of A_k x_(column k) over one row's blocks [begin, end); x holds 3 scalars per block
  // column. Reads one scalar past a column's 3 except at the last node's.
  // Four lanes: the row's three sums and a zero.
  Sum4 row_sums(int begin, int end, const Scalar* x) const;
  Vector3 row_product(int i, const Scalar* x) const {
    return row_sums(row_start_[i], row_start_[i + 1], x).template head<3>().matrix();
  }

  // f(i, row i's sums in four lanes) for every row i in [first, last).
  template <class F>
  void for_rows(int first, int last, const Scalar* x, F&& f) const {
    for (int i = first; i < last; ++i) f(i, row_sums(row_start_[i], row_start_[i + 1], x));
  }

  int rows() const { return static_cast<int>(row_start_.size()) - 1; }
  long long blocks() const { return row_start_.back(); }
  // The bytes one pass over every row reads of this object: values (padding included),
  // per block its x offset, per row its start.
  double bytes() const;

 private:
  using Lanes = PairLanes<Scalar>;
  void add_pair(typename Lanes::Acc (&acc)[3], const Scalar* a, const typename Lanes::X& x) const {
    if constexpr (Packed) {
      Lanes::template add_packed<0>(acc[0], a, x);
      Lanes::template add_packed<1>(acc[1], a + kColumn, x);
      Lanes::template add_packed<2>(acc[2], a + 2 * kColumn, x);
    } else {
      Lanes::template add_padded<0>(acc[0], a, x);
      Lanes::template add_padded<1>(acc[1], a + kColumn, x);
      Lanes::template add_padded<2>(acc[2], a + 2 * kColumn, x);
    }
  }

  std::vector<Scalar, Eigen::aligned_allocator<Scalar>> values_;
  std::vector<int> row_start_{0};  // the pattern's: row i holds blocks row_start_[i] ..
  std::vector<int> x_offset_;      // per block: 3 * its column
  int last_x_offset_ = -1;         // the last node's: its piece is read without the scalar past
};

// ---- definitions of the templates -----------------------------------------------------

template <class Scalar, bool Packed>
PairedBlocks<Scalar, Packed>::PairedBlocks(const ch07::BlockCsr<3, 3>& pattern)
    : values_(kBlock * pattern.column.size() + 1, Scalar(0)), row_start_(pattern.row_start) {
  x_offset_.resize(pattern.column.size());
  for (std::size_t k = 0; k < pattern.column.size(); ++k) x_offset_[k] = 3 * pattern.column[k];
  last_x_offset_ = 3 * (pattern.block_rows() - 1);
}

template <class Scalar, bool Packed>
template <class Source>
void PairedBlocks<Scalar, Packed>::fill(const Eigen::Matrix<Source, 3, 3>* values, int first,
                                        int last) {
  for (int i = first; i < last; ++i) {
    const int begin = row_start_[i], end = row_start_[i + 1], paired = (end - begin) & ~1;
    for (int r = 0; r < end - begin; ++r) {
      // A pair's column j at kColumn j, its odd block kOdd on; a single's column j at kOdd j.
      Scalar* a = values_.data() + kBlock * (begin + r - r % 2) + (r < paired ? r % 2 * kOdd : 0);
      const int stride = r < paired ? kColumn : kOdd;
      for (int j = 0; j < 3; ++j)
        for (int row = 0; row < 3; ++row)
          a[stride * j + row] = static_cast<Scalar>(values[begin + r](row, j));
    }
  }
}

template <class Scalar, bool Packed>
inline typename PairedBlocks<Scalar, Packed>::Sum4 PairedBlocks<Scalar, Packed>::row_sums(
    int begin, int end, const Scalar* x) const {
  const int paired_end = begin + ((end - begin) & ~1);
  const int* offset = x_offset_.data();
  // The last pair reads its odd piece with care if that is the last node (columns are
  // sorted: only a row's last block can be).
  const int safe_end =
      paired_end > begin && offset[paired_end - 1] == last_x_offset_ ? paired_end - 2 : paired_end;
  const Scalar* a = values_.data() + kBlock * begin;
  typename Lanes::Acc acc[3] = {Lanes::zero(), Lanes::zero(), Lanes::zero()};
  int k = begin;
  for (; k < safe_end; k += 2, a += 2 * kBlock)
    add_pair(acc, a, Lanes::pair(x + offset[k], x + offset[k + 1]));
  if (k < paired_end) {
    add_pair(acc, a, Lanes::pair_at_end(x + offset[k], x + offset[k + 1]));
    k += 2;
    a += 2 * kBlock;
  }
  if (k < end) {
    Lanes::template add_even<0>(acc[0], a, x + offset[k]);
    Lanes::template add_even<1>(acc[1], a + kOdd, x + offset[k]);
    Lanes::template add_even<2>(acc[2], a + 2 * kOdd, x + offset[k]);
  }
  return Lanes::total(acc);
}

template <class Scalar, bool Packed>
double PairedBlocks<Scalar, Packed>::bytes() const {
  return double(values_.size()) * sizeof(Scalar) +
         double(x_offset_.size() + row_start_.size()) * sizeof(int);
}

}  // namespace fem::ch14
