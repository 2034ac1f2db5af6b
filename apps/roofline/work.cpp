// The counts of work.hpp, by data model: chapters 01-06 (Eigen's compressed sparse matrix,
// common/'s element kernels), 07 (3x3 blocks), 08-09 (the fused element pass, block Jacobi),
// 10-11 (the V-cycle) and 12 (the V-cycle in float). Each formula says what it counts.
#include "apps/roofline/work.hpp"

#include <stdexcept>

#include "chapters/01_naive/stepper.hpp"
#include "chapters/02_noalias/stepper.hpp"
#include "chapters/03_indexed_access/stepper.hpp"
#include "chapters/04_system_composition/stepper.hpp"
#include "chapters/05_inplace_constraints/stepper.hpp"
#include "chapters/06_custom_pcg/stepper.hpp"
#include "chapters/07_block_sparse/stepper.hpp"
#include "chapters/08_element_kernels/stepper.hpp"
#include "chapters/10_multigrid/stepper.hpp"
#include "chapters/12_half_the_bytes/stepper.hpp"
#include "chapters/13_fewer_waits/stepper.hpp"

namespace fem::roofline {

namespace {

constexpr double kDouble = sizeof(double);
constexpr double kBlock = 9 * kDouble;  // a 3x3 block of doubles

// The vectors one PCG iteration streams besides the product and the preconditioner:
// x += a p (reads x and p, writes x), r -= a q (r, q; r), p = z + b p (z, p; p), and the
// product's p and q and the preconditioner's r and z; the dot products ride on those passes.
constexpr double kPcgStreams = 11;
// ... of which distinct vectors: x, r, p, q, z.
constexpr double kPcgVectors = 5;
// A constrained block S_i a_ij S_j: two 3x3 products.
constexpr double kConstraintBlockFlops = 90;

struct Mesh {
  double nodes, elements, dofs, vector_bytes;
};
Mesh sizes(const Scene& scene) {
  const double nodes = scene.mesh.num_nodes();
  return {nodes, double(scene.mesh.num_tets()), 3 * nodes, 3 * nodes * kDouble};
}

PhaseWork phase(const std::string& name, double bytes, double flops, double working_set) {
  return {name, bytes, flops, 0.0, working_set};
}

// A PCG solve: the initial residual's product and `iterations` iterations, each a product, a
// preconditioner and the vector streams. Working set: the matrix, the preconditioner, the
// vectors.
PhaseWork pcg(const Mesh& m, int iterations, double matrix, double matrix_flops,
              const PhaseWork& preconditioner) {
  const double passes = iterations + 1.0;
  PhaseWork w =
      phase("solve", passes * (matrix + preconditioner.bytes + kPcgStreams * m.vector_bytes),
            passes * (matrix_flops + preconditioner.flops_double + 10 * m.dofs),
            matrix + preconditioner.working_set + kPcgVectors * m.vector_bytes);
  w.flops_float = passes * preconditioner.flops_float;
  return w;
}

// Stored entries in the columns of the constrained nodes' dofs (= in their rows: A is
// symmetric), of a compressed matrix.
double constrained_entries(const Eigen::SparseMatrix<double>& A, const Scene& scene) {
  double entries = 0;
  for (const NodeConstraint& c : scene.constraints)
    for (int d = 0; d < 3; ++d)
      entries += A.outerIndexPtr()[3 * c.node + d + 1] - A.outerIndexPtr()[3 * c.node + d];
  return entries;
}

// Blocks in the block rows of the constrained nodes.
double constrained_blocks(const ch07::BlockSparseMatrix& A, const Scene& scene) {
  double blocks = 0;
  for (const NodeConstraint& c : scene.constraints)
    blocks += A.row_start[c.node + 1] - A.row_start[c.node];
  return blocks;
}

// common/'s element loop (chapters 01-07): reads each element's whole ElementRest (Dm^-1,
// volume, K0, X_e: common/element.hpp), its corners and x; writes R_e, f; reads gravity.
PhaseWork reference_forces(const Mesh& m) {
  const double bytes =
      m.elements * (sizeof(ElementRest) + sizeof(Eigen::Vector4i) + kBlock) + 3 * m.vector_bytes;
  return phase("forces", bytes, m.elements * reference_force_flops(), bytes);
}

// df/dx (01-07): per element K0, R_e and its corners read, the matrix written once (its
// values, and its indices read to find where).
PhaseWork reference_dfdx(const Mesh& m, double matrix) {
  const double bytes = m.elements * (sizeof(Matrix12d) + kBlock + sizeof(Eigen::Vector4i)) + matrix;
  return phase("dfdx", bytes, m.elements * reference_block_flops(), bytes);
}

// A = (1 + h alpha) M - (h beta + h^2) df/dx and b = h (f + df/dx (h + beta) v + ...): df/dx
// read, A written, an FMA per entry and a product with df/dx; M, v, f, f_ext read, b written.
PhaseWork reference_compose(const Mesh& m, double dfdx, double A, double entries) {
  const double bytes = dfdx + A + 5 * m.vector_bytes;
  return phase("compose", bytes, 4 * entries + 6 * m.dofs, bytes);
}

// Chapters 01-06: Eigen's compressed matrices. 01-04 filter by sparse products S A S^T into
// a second matrix (A read, the filtered matrix written); 05-06 filter in place, only the rows
// and columns of constrained nodes (read and written). Jacobi reads the inverse diagonal.
template <class S>
std::vector<PhaseWork> compressed_chapter(const S& stepper, const Scene& scene, int iterations,
                                          bool in_place) {
  const Mesh m = sizes(scene);
  const auto& dfdx = stepper.dfdx();
  const auto& A = stepper.system_matrix();
  const double matrix = matrix_bytes(A), entries = double(A.nonZeros());
  const double touched = constrained_entries(A, scene);
  const double filter_bytes =
      (in_place ? 2 * 2 * touched * kDouble : matrix_bytes(dfdx) + matrix) + 3 * m.vector_bytes;
  const PhaseWork jacobi = phase("jacobi", m.vector_bytes, m.dofs, m.vector_bytes);
  return {reference_forces(m), reference_dfdx(m, matrix_bytes(dfdx)),
          reference_compose(m, matrix_bytes(dfdx), matrix, entries),
          phase("constraints", filter_bytes, 2 * kConstraintBlockFlops * touched / 9, filter_bytes),
          pcg(m, iterations, matrix, 2 * entries, jacobi)};
}

// Block Jacobi (07-09): the inverse diagonal blocks, one 3x3 product per node.
PhaseWork block_jacobi(const Mesh& m) {
  return phase("block jacobi", m.nodes * kBlock, m.nodes * 15, m.nodes * kBlock);
}

// The constraints on 3x3 blocks, in place (07-12): the rows and columns of constrained nodes
// read and written, b read, S (b - A z) written.
PhaseWork block_constraints(const Mesh& m, const ch07::BlockSparseMatrix& A, const Scene& scene) {
  const double blocks = constrained_blocks(A, scene);
  const double bytes = 2 * 2 * blocks * kBlock + 2 * m.vector_bytes;
  return phase("constraints", bytes, 2 * kConstraintBlockFlops * blocks, bytes);
}

// Chapter 07: common/'s element loop on the block matrix; df/dx and A on the same pattern.
std::vector<PhaseWork> block_chapter(const ch07::BlockSparseStepper& stepper, const Scene& scene,
                                     int iterations) {
  const Mesh m = sizes(scene);
  const auto& A = stepper.system_matrix();
  const double matrix = matrix_bytes(A), entries = 9.0 * double(A.blocks.size());
  return {reference_forces(m), reference_dfdx(m, matrix),
          reference_compose(m, matrix, matrix, entries), block_constraints(m, A, scene),
          pcg(m, iterations, matrix, 2 * entries, block_jacobi(m))};
}

// Chapters 08-12: no df/dx. compose is what the elements do not touch: every block of A
// zeroed, the mass on the diagonal, b from gravity, M, v and f_ext. The fused pass reads
// each element's shape (Dm^-1, V mu, V lambda), its last two rotations (writing one back),
// its corners and block positions, x and v, and adds into every block of A and into b.
std::vector<PhaseWork> fused_start(const ch08::ElementKernelsStepper& stepper, const Mesh& m) {
  const auto& A = stepper.system_matrix();
  const double blocks = double(A.blocks.size()) * kBlock;
  const double compose = blocks + m.nodes * sizeof(int) + 5 * m.vector_bytes;
  const double per_element = sizeof(ch08::ElementShape) + 3 * sizeof(Eigen::Quaterniond) +
                             sizeof(Eigen::Vector4i) + sizeof(std::array<int, 16>);
  const double pass = m.elements * per_element + 2 * blocks + 4 * m.vector_bytes;
  return {phase("forces", pass, m.elements * fused_element_flops(), pass),
          phase("compose", compose, 4 * m.dofs, compose)};
}

}  // namespace

double matrix_bytes(const Eigen::SparseMatrix<double>& m) {
  using Index = Eigen::SparseMatrix<double>::StorageIndex;
  return double(m.nonZeros()) * (sizeof(double) + sizeof(Index)) +
         double(m.outerSize() + 1) * sizeof(Index);
}

namespace {

// Chapters 08-12: the fused pass and compose, the block constraints, the PCG with its
// preconditioner, and what the preconditioner's prepare does once per solve.
std::vector<PhaseWork> fused_chapter(const ch08::ElementKernelsStepper& stepper, const Scene& scene,
                                     int iterations, const PhaseWork& preconditioner,
                                     double prepare_bytes) {
  const Mesh m = sizes(scene);
  const auto& A = stepper.system_matrix();
  const double matrix = matrix_bytes(A), entries = 9.0 * double(A.blocks.size());
  const std::vector<PhaseWork> start = fused_start(stepper, m);
  PhaseWork solve = pcg(m, iterations, matrix, 2 * entries, preconditioner);
  solve.bytes += prepare_bytes;
  return {start[0], start[1], block_constraints(m, A, scene), solve};
}

// The V-cycle chapters: 10 and 11 in double; 12 in float (its arithmetic as the stepper says).
// prepare: the fine level's inverse diagonal from A's diagonal blocks (read, written), and in
// chapter 12 every fine block read in double and written in float.
std::vector<PhaseWork> multigrid_chapter(const ch10::MultigridStepper& stepper, const Scene& scene,
                                         int iterations, bool in_float, bool float_arithmetic) {
  const Mesh m = sizes(scene);
  const ch10::Multigrid& mg = stepper.multigrid();
  const int scalar = in_float ? 4 : 8;
  const PhaseWork v_cycle =
      v_cycle_work(multigrid_levels(mg), smoother_products(mg), scalar, float_arithmetic);
  double prepare = m.nodes * (kBlock + 9.0 * scalar);
  if (in_float) prepare += double(stepper.system_matrix().blocks.size()) * (kBlock + 9.0 * 4);
  return fused_chapter(stepper, scene, iterations, v_cycle, prepare);
}

template <class S>
const S* as(const Stepper& stepper) {
  return dynamic_cast<const S*>(&stepper);
}

}  // namespace

std::vector<PhaseWork> count_work(const Stepper& wrapped, const Scene& scene, int it,
                                  std::string& counted_as) {
  const Stepper& s = unwrapped(wrapped);
  // Most derived first: 13 derives from 12, 12 from 11, 11 from 10, 10 from 09, 09 from 08.
  if (const auto* c = as<ch13::FewerWaitsStepper>(s)) {
    // Chapter 12's matrices and cycle; its single-reduction PCG streams two more vectors per
    // iteration (w = A s written and read, q updated: read and written).
    counted_as = "13";
    std::vector<PhaseWork> work = multigrid_chapter(*c, scene, it, true, true);
    work.back().bytes += (it + 1.0) * 4 * sizes(scene).vector_bytes;
    work.back().working_set += 2 * sizes(scene).vector_bytes;
    return work;
  }
  if (const auto* c = as<ch12::HalfBytesStepper>(s)) {
    counted_as = "12";
    return multigrid_chapter(*c, scene, it, true, c->arithmetic() == ch12::Arithmetic::single);
  }
  if (const auto* c = as<ch10::MultigridStepper>(s)) {
    counted_as = as<ch11::NodeOrderStepper>(s) ? "11" : "10";
    return multigrid_chapter(*c, scene, it, false, false);
  }
  if (const auto* c = as<ch08::ElementKernelsStepper>(s)) {
    counted_as = as<ch09::ThreadsStepper>(s) ? "09" : "08";
    return fused_chapter(*c, scene, it, block_jacobi(sizes(scene)),
                         sizes(scene).nodes * 2 * kBlock);
  }
  if (const auto* c = as<ch07::BlockSparseStepper>(s))
    return counted_as = "07", block_chapter(*c, scene, it);
  if (const auto* c = as<ch06::CustomPcgStepper>(s))
    return counted_as = "06", compressed_chapter(*c, scene, it, true);
  if (const auto* c = as<ch05::InplaceConstraintsStepper>(s))
    return counted_as = "05", compressed_chapter(*c, scene, it, true);
  if (const auto* c = as<ch04::SystemCompositionStepper>(s))
    return counted_as = "04", compressed_chapter(*c, scene, it, false);
  if (const auto* c = as<ch03::IndexedAccessStepper>(s))
    return counted_as = "03", compressed_chapter(*c, scene, it, false);
  if (const auto* c = as<ch02::NoAliasStepper>(s))
    return counted_as = "02", compressed_chapter(*c, scene, it, false);
  if (const auto* c = as<ch01::NaiveStepper>(s))
    return counted_as = "01", compressed_chapter(*c, scene, it, false);
  throw std::invalid_argument(
      "the roofline counts the course's chapters' data: this stepper is none of them");
}

}  // namespace fem::roofline
