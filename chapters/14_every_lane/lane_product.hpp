// The PCG's product q = A p in double with two blocks per 512-bit register (lanes.hpp,
// paired_blocks.hpp; on narrower builds the same lanes as two arrays of 4). A part for a
// stepper: built on the system matrix's pattern once, its values copied in by rows after
// each assembly, then called on the PCG's fixed row chunks. Its sums run in another order
// than the 3x3 products of the block rows (six partial sums a row, not one), so q differs
// from theirs in the last bits (a few ulps of the row's largest product), the same for any
// thread count.
#pragma once

#include <Eigen/Core>

#include "chapters/07_block_sparse/block_sparse.hpp"
#include "chapters/14_every_lane/paired_blocks.hpp"
#include "chapters/work.hpp"

namespace fem::ch14 {

template <bool Packed>
class PairProduct {
 public:
  PairProduct() = default;
  // The layout of A's pattern (set-up).
  explicit PairProduct(const ch07::BlockSparseMatrix& A) : blocks_(A) {}

  // A's values of rows [first, last), after each assembly, by every thread on its rows.
  void fill(const ch07::BlockSparseMatrix& A, int first, int last) {
    blocks_.fill(A.blocks.data(), first, last);
  }

  // y_i = (A x)_i on rows [first, last); x read one scalar past each node's 3 except the last.
  void multiply_rows(const Eigen::VectorXd& x, Eigen::VectorXd& y, int first, int last) const {
    for (int i = first; i < last; ++i)
      y.template segment<3>(3 * i) = blocks_.row_product(i, x.data());
  }

  const PairedBlocks<double, Packed>& blocks() const { return blocks_; }

  // One product over every row: its matrix and p read, q written fresh; 18 flops a block.
  PhaseWork work() const {
    const double v = 3.0 * sizeof(double) * blocks_.rows();
    PhaseWork w;
    w.phase = "product";
    w.bytes_read = blocks_.bytes() + v;
    w.bytes_written = v;
    w.bytes_allocated = v;
    w.flops_double = 18.0 * double(blocks_.blocks());
    w.working_set = blocks_.bytes() + 2 * v;
    return w;
  }

 private:
  PairedBlocks<double, Packed> blocks_;
};
// The blocks packed, 72 bytes a block (the faster here: the product is bound by its bytes
// once its lanes are busy); padded, 96, for the comparison.
using LaneProduct = PairProduct<true>;
using PaddedLaneProduct = PairProduct<false>;

}  // namespace fem::ch14
