// The solve's product q = A p in double with two blocks per 512-bit register (lanes.hpp,
// paired_blocks.hpp; on narrower builds the same lanes as two arrays of 4): a Product part
// (chapter 08's contract), built on the system matrix's pattern once, its values copied in by
// the solver's team after each assembly (prepare), then called on the solver's row chunks. Its
// sums run in another order than the 3x3 products of the block rows (six partial sums a row,
// not one), so q differs from theirs in the last bits (a few ulps of the row's largest
// product), the same for any thread count; the PCG converges to the same tolerance.
#pragma once

#include <Eigen/Core>

#include "chapters/07_block_sparse/block_sparse.hpp"
#include "chapters/08_element_kernels/contract.hpp"
#include "chapters/09_threads/parallel.hpp"
#include "chapters/09_threads/parallel_pcg.hpp"
#include "chapters/14_every_lane/paired_blocks.hpp"
#include "chapters/work.hpp"

namespace fem::ch14 {

template <bool Packed>
class PairProduct final : public ch08::ProductPart {
 public:
  struct Params {};
  static constexpr const char* kName = Packed ? "A's blocks in double pair lanes, packed"
                                              : "A's blocks in double pair lanes, padded";
  static constexpr std::string_view kChapter = FEM_PART_CHAPTER;

  PairProduct() = default;
  // The layout of A's pattern (set-up), and the fixed row chunks its copy is shared out on.
  explicit PairProduct(const ch07::BlockSparseMatrix& A) : blocks_(A), chunks_(A) {}
  PairProduct(const ch08::PartSetup& setup, const Params&) : PairProduct(setup.system.A) {}

  // A's values into the lanes, after each assembly, by every thread of the solver's team on
  // its chunks (a barrier at the end: every row is ready before the first product).
  void prepare(const ch07::BlockSparseMatrix& A) override {
    for (const int c : ch09::StaticShare(chunks_.count()))
      fill(A, chunks_.start[c], chunks_.start[c + 1]);
  }
  // A's values of rows [first, last).
  void fill(const ch07::BlockSparseMatrix& A, int first, int last) {
    blocks_.fill(A.blocks.data(), first, last);
  }

  // y_i = (A x)_i on rows [first, last); x read one scalar past each node's 3 except the last.
  void multiply_rows(const Eigen::VectorXd& x, Eigen::VectorXd& y, int first,
                     int last) const override {
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
  ch09::RowChunks chunks_;
};
// The blocks packed, 72 bytes a block (the faster here: the product is bound by its bytes
// once its lanes are busy); padded, 96, for the comparison.
using LaneProduct = PairProduct<true>;
using PaddedLaneProduct = PairProduct<false>;

}  // namespace fem::ch14
