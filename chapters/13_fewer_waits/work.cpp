#include "chapters/13_fewer_waits/work.hpp"

#include <memory>

#include "chapters/09_threads/parallel.hpp"
#include "chapters/09_threads/work.hpp"
#include "chapters/10_multigrid/work.hpp"
#include "chapters/12_half_the_bytes/work.hpp"

namespace fem::ch13 {

ch08::PreconditionerWork preconditioner_work(const FusedPreconditioner& part,
                                             const ch08::WorkInput& in) {
  return ch10::multigrid_work(part.multigrid(), in, sizeof(float), true);
}

PhaseWork solver_work(const SingleReductionSolver&, const ch08::WorkInput& in,
                      const ch08::PreconditionerWork& preconditioner) {
  // single_reduction_pcg.cpp, per iteration: r read for gamma = r . s where the cycle writes s;
  // the product w = A s (the matrix and s read, w written fresh) with delta = s . w; the update
  // loop reads s, p, w, q, y and r and writes p, q, y and r back, with ||r||^2.
  const ch01::MeshSizes& m = in.m;
  const double v = m.vector_bytes, matrix = in.product.matrix_bytes;
  const PhaseWork own = ch01::phase_work("pcg", matrix + 8 * v, 5 * v, v,
                                         in.product.flops + 14 * m.dofs, matrix + 6 * v);
  return ch08::solve_work(in, own, preconditioner);
}

namespace {

// The iteration's vectors, of the fine level's size, on chapter 09's fixed row chunks.
struct IterationVectors {
  ch09::RowChunks chunks;
  Eigen::VectorXd y, r, s, w, p, q;
  std::vector<double> rr, gamma, delta;
};

std::shared_ptr<IterationVectors> iteration_vectors(const ch07::BlockSparseMatrix& A) {
  auto v = std::make_shared<IterationVectors>();
  v->chunks = ch09::RowChunks(A);
  const Eigen::Index n = 3 * Eigen::Index(A.block_rows());
  // Small finite values that stay finite however often the updates run (p = s + p / 2).
  for (Eigen::VectorXd* x : {&v->y, &v->r, &v->s, &v->w, &v->p, &v->q})
    *x = Eigen::VectorXd::LinSpaced(n, 1e-3, 1.0);
  v->rr.assign(v->chunks.count(), 0.0);
  v->gamma.assign(v->chunks.count(), 0.0);
  v->delta.assign(v->chunks.count(), 0.0);
  return v;
}

}  // namespace

std::vector<PartKernel> solver_kernels(SingleReductionSolver&, const ch08::KernelInput& in) {
  const auto v = iteration_vectors(in.A);
  const double vector = 8.0 * double(v->s.size()), dofs = double(v->s.size());
  const double matrix = in.product_work.matrix_bytes;
  // gamma = r . s, which the cycle's last loop sums as it writes s (precondition_and_product's
  // finish), timed here with the product: the solver's work, not the cycle's.
  const PhaseWork product = ch01::phase_work("product", matrix + 2 * vector, vector, vector,
                                             in.product_work.flops + 4 * dofs, matrix + 3 * vector);
  const PhaseWork updates =
      ch01::phase_work("updates", 6 * vector, 4 * vector, 0.0, 10 * dofs, 6 * vector);
  const ch08::ProductPart* A = &in.product;
  using ch09::StaticShare;
  return {ch09::part_kernel("product w = A s, r . s and s . w", "pcg", product, in.passes,
                            [v, A] {
                              for (const int c : StaticShare(v->chunks.count())) {
                                const int f = v->chunks.first_dof(c), n = v->chunks.dofs(c);
                                v->gamma[c] = v->r.segment(f, n).dot(v->s.segment(f, n));
                                v->delta[c] = single_reduction_product(
                                    *A, v->s, v->w, v->chunks.start[c], v->chunks.start[c + 1]);
                              }
                            }),
          ch09::part_kernel("recurrences and r . r", "pcg", updates, in.passes, [v] {
            for (const int c : StaticShare(v->chunks.count()))
              v->rr[c] = single_reduction_update(1e-3, 0.5, v->s, v->w, v->p, v->q, v->y, v->r,
                                                 ch09::ChunkFilter{}, v->chunks.start[c],
                                                 v->chunks.start[c + 1]);
          })};
}

std::vector<PartKernel> preconditioner_kernels(FusedPreconditioner& part,
                                               const ch08::KernelInput& in) {
  return ch12::preconditioner_kernels(part.reduced(), in);
}

}  // namespace fem::ch13
