// Each chapter's work, counted from its own data: per phase of the step, the bytes that must
// cross from memory and the flops, from the data structures the stepper holds (its matrices'
// values and indices, its vectors, every level of its V-cycle, its element data) and the
// iterations its last solve took.
//
// The model, kept simple so that a student can check it by hand:
//  - bytes: every array a phase reads or writes, counted once per pass over it (the
//    compulsory traffic: what would cross from memory if every cache line were used whole
//    and never fetched twice). A chapter that reads an array twice, or fetches lines it
//    half uses, pays that as distance from its bound, which is the point of the bound.
//  - flops: the arithmetic the phase requires, a multiply or an add each (a multiply-add is
//    2): per block product of a matrix, per entry of a vector operation, and per element of
//    the element pass, counted term by term from the formulas of chapter 08's kernels
//    (element_flops.cpp). An SVD where one Newton step would do counts as the Newton step:
//    what the SVD does beyond it is distance too.
//  - working set: the distinct bytes one pass touches; the level of the hierarchy that holds
//    it gives the bandwidth the phase's bytes are charged at.
#pragma once

#include <Eigen/SparseCore>
#include <string>
#include <vector>

#include "chapters/07_block_sparse/block_sparse.hpp"
#include "common/scene.hpp"
#include "common/stepper.hpp"

namespace fem::ch10 {
class Multigrid;
}

namespace fem::roofline {

struct PhaseWork {
  std::string phase;  // a StepProfile phase: "forces", "dfdx", "compose", "constraints", "solve"
  double bytes = 0.0;
  double flops_double = 0.0;
  double flops_float = 0.0;  // chapter 12's V-cycle: float arithmetic, the float peak's
  double working_set = 0.0;  // bytes one pass over the phase's data touches
};

// The phases of one step of `stepper` (the registry's, unwrapped() inside) on `scene`, whose
// solve took `iterations` (StepProfile::cg_iterations; the lesson passes the median of its
// measured steps). `counted_as` gets the course chapter whose data model was
// read (a student's variant is counted as its original: see the lesson's text). Throws
// std::invalid_argument for a stepper of no course chapter.
std::vector<PhaseWork> count_work(const Stepper& stepper, const Scene& scene, int iterations,
                                  std::string& counted_as);

// ---- the counts the phases are made of (the tests check them) ---------------------------

// Values and indices of a compressed sparse matrix (Eigen's CSC: value, inner index per
// entry, outer index per column plus one).
double matrix_bytes(const Eigen::SparseMatrix<double>& m);
// Blocks and indices of chapter 07's block compressed rows, at `scalar` bytes per number.
template <int R, int C>
double matrix_bytes(const ch07::BlockCsr<R, C>& m, int scalar = 8) {
  return double(m.blocks.size()) * R * C * scalar +
         double(m.column.size() + m.row_start.size()) * sizeof(int);
}

// One level of a V-cycle hierarchy as the counts need it (chapter 10's Multigrid through
// multigrid_levels, the one place that reads its API).
struct LevelSize {
  int block = 3;           // 3 on the mesh, 6 on the aggregates
  long long nodes = 0;     // block rows
  long long blocks = 0;    // stored blocks of the level's matrix
  long long transfer = 0;  // blocks of P to the next level (0 on the coarsest)
  bool coarsest = false;   // solved by a dense Cholesky factor
};
std::vector<LevelSize> multigrid_levels(const ch10::Multigrid& multigrid);
// Matrix products per level per V-cycle: pre- and post-smoothing and the residual.
int smoother_products(const ch10::Multigrid& multigrid);

// One V-cycle's bytes and flops over `levels`, numbers and vectors at `scalar` bytes
// (8: chapter 10's double, 4: chapter 12's float); its flops in float arithmetic or double.
PhaseWork v_cycle_work(const std::vector<LevelSize>& levels, int products, int scalar,
                       bool float_arithmetic);

// Flops of one element, term by term (element_flops.cpp).
double fused_element_flops();    // chapter 08's fused pass (08-12)
double reference_force_flops();  // common/'s rotation and element force (01-07)
double reference_block_flops();  // common/'s 16 blocks R K0 R^T (01-07)

}  // namespace fem::roofline
