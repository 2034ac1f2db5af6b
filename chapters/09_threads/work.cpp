#include "chapters/09_threads/work.hpp"

#include <memory>

#include "chapters/09_threads/parallel.hpp"

namespace fem::ch09 {

ch08::ElementWork element_work(const ThreadedElements&, const ch08::WorkInput& in) {
  return ch08::fused_pass_work(in);
}

ch08::PreconditionerWork preconditioner_work(const JacobiOnChunks&, const ch08::WorkInput& in) {
  return ch08::block_jacobi_work(in);
}

PhaseWork solver_work(const ParallelPcgSolver&, const ch08::WorkInput& in,
                      const ch08::PreconditionerWork& preconditioner) {
  return ch08::pcg_solve_work(in, preconditioner);
}

ExecutedWork element_counters(const ThreadedElements& part, double) {
  return ch08::fused_counters(part.fused());
}

double team_size(const TeamOfThreads& team) { return team.adaptive_team().team(); }

}  // namespace fem::ch09

namespace fem::ch09 {

namespace {

// The PCG's vectors, of the fine level's size, on the fixed row chunks.
struct PcgVectors {
  RowChunks chunks;
  Eigen::VectorXd y, r, s, p, q;
  std::vector<double> rr, pq;
};

std::shared_ptr<PcgVectors> pcg_vectors(const BlockSparseMatrix& A) {
  auto v = std::make_shared<PcgVectors>();
  v->chunks = RowChunks(A);
  const Eigen::Index n = 3 * Eigen::Index(A.block_rows());
  // Small finite values that stay finite however often the updates run (p = s + p / 2).
  for (Eigen::VectorXd* x : {&v->y, &v->r, &v->s, &v->p, &v->q})
    *x = Eigen::VectorXd::LinSpaced(n, 1e-3, 1.0);
  v->rr.assign(v->chunks.count(), 0.0);
  v->pq.assign(v->chunks.count(), 0.0);
  return v;
}

}  // namespace

PartKernel part_kernel(const std::string& name, const std::string& part, const PhaseWork& work,
                       double calls, std::function<void()> run) {
  PartKernel k;
  k.name = name;
  k.part = part;
  k.work = work;
  k.calls = calls;
  k.run = std::move(run);
  return k;
}

std::vector<PartKernel> solver_kernels(ParallelPcgSolver&, const ch08::KernelInput& in) {
  const auto v = pcg_vectors(in.A);
  const double vector = 8.0 * double(v->p.size()), dofs = double(v->p.size());
  const double matrix = in.product_work.matrix_bytes;
  const PhaseWork product = ch01::phase_work("product", matrix + vector, vector, vector,
                                             in.product_work.flops + 2 * dofs, matrix + 2 * vector);
  const PhaseWork update =
      ch01::phase_work("update", 4 * vector, 2 * vector, 0.0, 6 * dofs, 4 * vector);
  const PhaseWork next =
      ch01::phase_work("next direction", 2 * vector, vector, 0.0, 2 * dofs, 2 * vector);
  const ch08::ProductPart* A = &in.product;
  return {part_kernel("product q = A p and p . q", "pcg", product, in.passes,
                      [v, A] {
                        for (const int c : StaticShare(v->chunks.count()))
                          v->pq[c] = pcg_product(*A, v->p, v->q, v->chunks.start[c],
                                                 v->chunks.start[c + 1]);
                      }),
          part_kernel("update y, r and r . r", "pcg", update, in.passes,
                      [v] {
                        for (const int c : StaticShare(v->chunks.count()))
                          v->rr[c] = pcg_update(1e-3, v->p, v->q, v->y, v->r, ChunkFilter{},
                                                v->chunks.start[c], v->chunks.start[c + 1]);
                      }),
          part_kernel("next direction p = s + beta p", "pcg", next, in.passes, [v] {
            for (const int c : StaticShare(v->chunks.count()))
              pcg_next_direction(0.5, v->s, v->p, v->chunks.start[c], v->chunks.start[c + 1]);
          })};
}

std::vector<PartKernel> preconditioner_kernels(JacobiOnChunks& part, const ch08::KernelInput& in) {
  const auto v = pcg_vectors(in.A);
  JacobiOnChunks* jacobi = &part;
  jacobi->prepare(in.A);  // outside a team: on this thread
  const PhaseWork inverses = ch07::block_jacobi(in.m);
  const PhaseWork work = ch01::phase_work(
      "block jacobi", in.m.vector_bytes + inverses.bytes_read, in.m.vector_bytes, in.m.vector_bytes,
      inverses.flops_double, 2 * in.m.vector_bytes + inverses.working_set);
  return {part_kernel("block Jacobi s = D^-1 r", "preconditioner", work, in.passes, [v, jacobi] {
    for (const int c : StaticShare(v->chunks.count()))
      jacobi->apply_rows(v->chunks.start[c], v->chunks.start[c + 1], v->r, v->s);
  })};
}

}  // namespace fem::ch09
