#include "chapters/08_element_kernels/work.hpp"

#include "chapters/07_block_sparse/work.hpp"

namespace fem::ch08 {

namespace {

constexpr double kBlock = 9 * sizeof(double);  // a 3x3 block of doubles
using ch01::kMatMat3Flops;
using ch01::kMatVec3Flops;
constexpr double kQuaternionProductFlops = 28.0;  // 16 multiplies, 12 adds

}  // namespace

ElementWork fused_pass_work(const WorkInput& in) {
  const ch01::MeshSizes& m = in.m;
  const double blocks = double(in.A.blocks.size()) * kBlock, v = m.vector_bytes;
  // compose: every block of A zeroed, the mass on the diagonal (the diagonal index read); b
  // from gravity, M, v and f_ext (fresh lines). A's bytes are zeroed, priced at the roof of
  // the same zeroing loop (whole-line vector stores with GCC 12 at -march=native on a Zen 5,
  // or a memset where the compiler makes one), which stores zeros faster than the write roof's
  // stores of other values: a Zen 5 ran the 82k-node beam's compose at 105% of the bound that
  // charged them at the write roof.
  PhaseWork compose = ch01::phase_work("compose", m.nodes * sizeof(int) + 4 * v, blocks + v, v,
                                       4 * m.dofs, blocks + m.nodes * sizeof(int) + 5 * v);
  compose.bytes_zeroed = blocks;
  // The fused pass: per element its shape, its last two rotations (both written back), its
  // corners and block positions; x and v; every block of A and b read and added into.
  const double per_element = sizeof(ElementShape) + 2 * sizeof(Eigen::Quaterniond) +
                             sizeof(Eigen::Vector4i) + sizeof(std::array<int, 16>);
  const double rotations = m.elements * 2 * sizeof(Eigen::Quaterniond);
  const PhaseWork forces = ch01::phase_work(
      "forces", m.elements * per_element + blocks + 3 * v, rotations + blocks + v, 0.0,
      m.elements * fused_element_flops() + rotation_flops(in.counts, m.elements),
      m.elements * per_element + blocks + 3 * v);
  return {forces, compose};
}

PhaseWork pcg_solve_work(const WorkInput& in, const PreconditionerWork& preconditioner) {
  // The PCG's own kernels as chapter 01 counts them: the product and three vector updates.
  const double v = in.m.vector_bytes, matrix = in.product.matrix_bytes;
  const PhaseWork own = ch01::phase_work("pcg", matrix + v + 3 * 2 * v, v + 3 * v, v,
                                         in.product.flops + 10 * in.m.dofs, matrix + 5 * v);
  return solve_work(in, own, preconditioner);
}

PhaseWork solve_work(const WorkInput& in, const PhaseWork& own,
                     const PreconditionerWork& preconditioner) {
  PhaseWork solve = ch01::pcg_work(in.m, in.counts.cg_iterations, own, preconditioner.apply);
  const double read = preconditioner.prepare_read + in.product.prepare_read;
  const double written = preconditioner.prepare_written + in.product.prepare_written;
  solve.add_part(ch01::phase_work("prepare", read, written, written, 0.0, read + written), 1.0);
  return solve;
}

PreconditionerWork block_jacobi_work(const WorkInput& in) {
  return {ch07::block_jacobi(in.m), in.m.nodes * kBlock, in.m.nodes * kBlock};
}

ElementWork element_work(const SerialElements&, const WorkInput& in) { return fused_pass_work(in); }

ProductWork product_work(const AssembledProduct&, const BlockSparseMatrix& A) {
  // The blocks, their column indices and row starts (ch07::matrix_bytes), 2 flops an entry.
  return {ch07::matrix_bytes(A), 2.0 * 9.0 * double(A.blocks.size())};
}

PreconditionerWork preconditioner_work(const BlockJacobi&, const WorkInput& in) {
  return block_jacobi_work(in);
}

PhaseWork solver_work(const SerialPcg&, const WorkInput& in,
                      const PreconditionerWork& preconditioner) {
  return pcg_solve_work(in, preconditioner);
}

ExecutedWork fused_counters(const FusedElements& e) {
  const double steps = e.shapes().empty() ? 0.0 : double(e.total_rotations()) / e.shapes().size();
  return {steps, double(e.total_rotations()), double(e.total_newton_iterations()),
          double(e.total_fallbacks())};
}

ExecutedWork element_counters(const SerialElements& part, double) {
  return fused_counters(part.fused());
}

double fused_element_flops() {
  // element_kernels.cpp, FusedElements::terms and scatter.
  const double edges = 18.0;                                // Ds and Dv: 18 differences
  const double deformation = kMatMat3Flops;                 // F = Ds Dm^-1
  const double prediction = 2.0 * kQuaternionProductFlops;  // R_k R_(k-1)^T R_k
  const double gradients = kMatMat3Flops + 6.0;  // r_a = R g_a (a = 1..3), r_0 = -(r_1 + r_2 + r_3)
  const double strain = 18.0 + kMatMat3Flops;    // G = (Ds + s Dv) r^T
  const double stress = 9.0 + 9.0 + 3.0 + 6.0;   // P = V mu (G + G^T), trace, diagonal terms
  const double rhs = 4.0 * kMatVec3Flops + 12.0;  // -h P r_a for the 4 corners
  // stiffness_blocks, 10 distinct blocks: the outer product r_b r_a^T (9), its two scaled
  // terms and their sum (27), the dot product (5), the diagonal term (4).
  const double blocks = 10.0 * (9.0 + 27.0 + 5.0 + 4.0);
  const double scatter = 12.0 + 16.0 * 9.0;  // b += 4 corner terms, A += 16 blocks
  return edges + deformation + prediction + gradients + strain + stress + rhs + blocks + scatter;
}

double newton_iteration_flops() {
  // element_kernels.cpp, newton_polar_rotation's loop body.
  const double rotation = 12.0 + 12.0;                           // the unnormalized matrix of q
  const double residual = kMatMat3Flops + 3.0;                   // A = R_q^T F, axial(A - A^T)
  const double hessian = 12.0 + 2.0 + 3.0;                       // H = -(A + A^T) / 2, + tr(A) I
  const double threshold = 3.0 + 4.0;                            // |q|^2, its cube times the scale
  const double solve = 3.0 + 14.0 + 27.0 + kMatVec3Flops + 3.0;  // minors, det, adjugate, x
  const double update = 3.0 + kQuaternionProductFlops + 5.0;     // q (1, w/2), |w|^2
  return rotation + residual + hessian + threshold + solve + update;
}

double newton_finish_flops() {
  // The check before the loop (|F|^2, det F, the scale), the normalization, the matrix.
  return 17.0 + 14.0 + 5.0 + 8.0 + 24.0;
}

double rotation_flops(const WorkCounts& counts, double elements) {
  const ExecutedWork& e = counts.per_step;
  if (e.rotations <= 0) return elements * (newton_iteration_flops() + newton_finish_flops());
  return e.rotation_iterations * newton_iteration_flops() + e.rotations * newton_finish_flops();
}

}  // namespace fem::ch08
