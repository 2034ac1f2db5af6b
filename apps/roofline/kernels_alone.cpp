#include "apps/roofline/kernels_alone.hpp"

#include <algorithm>
#include <chrono>
#include <limits>
#include <memory>

#include "chapters/01_naive/work.hpp"
#include "chapters/07_block_sparse/work.hpp"
#include "chapters/09_threads/parallel.hpp"
#include "chapters/09_threads/parallel_pcg.hpp"
#include "chapters/09_threads/stepper.hpp"
#include "chapters/10_multigrid/work.hpp"
#include "chapters/12_half_the_bytes/reduced_kernels.hpp"
#include "chapters/12_half_the_bytes/stepper.hpp"
#include "common/lesson.hpp"
#include "common/threads.hpp"

namespace fem::roofline {

namespace {

constexpr int kTimings = 15;         // timings per kernel; the best is kept
constexpr double kMinTiming = 2e-3;  // seconds: calls per timing doubled up to this
constexpr int kSteps = 3;            // steps before the kernels run: A, the hierarchy, its vectors

KernelAlone kernel(const std::string& name, const std::string& part, const PhaseWork& work,
                   double calls) {
  KernelAlone k;
  k.name = name;
  k.part = part;
  k.work = work;
  k.calls = calls;
  return k;
}

// The PCG's vectors, of the fine level's size, on chapter 09's fixed row chunks.
struct PcgVectors {
  ch09::RowChunks chunks;
  Eigen::VectorXd y, r, s, p, q;
  std::vector<double> rr, rs;
};

std::shared_ptr<PcgVectors> pcg_vectors(const ch07::BlockSparseMatrix& A) {
  auto v = std::make_shared<PcgVectors>();
  v->chunks = ch09::RowChunks(A);
  const Eigen::Index n = 3 * Eigen::Index(A.block_rows());
  // Small finite values that stay finite however often the updates run (p = s + p / 2).
  for (Eigen::VectorXd* x : {&v->y, &v->r, &v->s, &v->p, &v->q})
    *x = Eigen::VectorXd::LinSpaced(n, 1e-3, 1.0);
  v->rr.assign(v->chunks.count(), 0.0);
  v->rs.assign(v->chunks.count(), 0.0);
  return v;
}

// The PCG's own kernels, which its count takes as one part ("pcg", ch01::pcg_work): the
// product q = A p (chapter 07's block rows on chapter 09's chunks) and the vector updates of
// chapter 09's iteration (x += a p, r -= a q, r . r, r . s, p = s + b p), once per pass.
std::vector<KernelAlone> pcg_kernels(const ch09::ThreadsStepper& stepper, double passes) {
  const ch07::BlockSparseMatrix& A = stepper.system_matrix();
  const auto v = pcg_vectors(A);
  const double vector = 8.0 * double(v->p.size()), dofs = double(v->p.size());
  const double matrix = ch07::matrix_bytes(A), entries = 9.0 * double(A.blocks.size());
  KernelAlone product = kernel("product q = A p", "pcg",
                               ch01::phase_work("product", matrix + vector, vector, vector,
                                                2 * entries, matrix + 2 * vector),
                               passes);
  product.run = [v, &A] {
    for (const int c : ch09::StaticShare(v->chunks.count()))
      A.multiply_rows(v->p, v->q, v->chunks.start[c], v->chunks.start[c + 1]);
  };
  KernelAlone updates = kernel(
      "vector updates and dot products", "pcg",
      ch01::phase_work("updates", 6 * vector, 3 * vector, 0.0, 10 * dofs, 5 * vector), passes);
  updates.run = [v] {
    for (const int c : ch09::StaticShare(v->chunks.count())) {
      const int first = v->chunks.first_dof(c), size = v->chunks.dofs(c);
      v->y.segment(first, size) += 1e-3 * v->p.segment(first, size);
      v->r.segment(first, size) -= 1e-3 * v->q.segment(first, size);
      v->rr[c] = v->r.segment(first, size).squaredNorm();
      v->rs[c] = v->r.segment(first, size).dot(v->s.segment(first, size));
      v->p.segment(first, size) = v->s.segment(first, size) + 0.5 * v->p.segment(first, size);
    }
  };
  return {product, updates};
}

// Chapter 09's block Jacobi, s = D^-1 r chunk by chunk: the count's "preconditioner" part
// (r read and s written, ch01::pcg_work, with the inverses, ch07::block_jacobi).
KernelAlone block_jacobi_kernel(const ch09::ThreadsStepper& stepper, const Scene& scene,
                                double passes) {
  const ch07::BlockSparseMatrix& A = stepper.system_matrix();
  const auto v = pcg_vectors(A);
  std::vector<int> diagonal(A.block_rows());
  for (int i = 0; i < A.block_rows(); ++i) diagonal[i] = A.find(i, i);
  auto jacobi = std::make_shared<ch09::BlockJacobi>(diagonal);
  jacobi->prepare(A, v->chunks);  // outside a team: on this thread
  const ch01::MeshSizes m = ch01::mesh_sizes(scene);
  const PhaseWork inverses = ch07::block_jacobi(m);
  const PhaseWork work = ch01::phase_work("block jacobi", m.vector_bytes + inverses.bytes_read,
                                          m.vector_bytes, m.vector_bytes, inverses.flops_double,
                                          2 * m.vector_bytes + inverses.working_set);
  KernelAlone k = kernel("block Jacobi s = D^-1 r", "preconditioner", work, passes);
  k.run = [v, jacobi] {
    for (const int c : ch09::StaticShare(v->chunks.count()))
      jacobi->apply_rows(v->chunks.start[c], v->chunks.start[c + 1], v->r, v->s);
  };
  return k;
}

// Chapter 12's smoothing step on its fine float level (chapter 10's polynomial step, a step
// after the first: it reads x, b and the direction and writes y and the direction), counted
// as chapter 10 counts one of the level's products; `products` of them per V-cycle.
template <class Real>
KernelAlone smoothing_kernel(ch12::HalfBytesStepper& stepper, ch12::ReducedVCycle<Real>& cycle,
                             double passes) {
  const ch10::Multigrid& mg = stepper.multigrid();
  const std::vector<ch10::LevelSize> levels = ch10::multigrid_levels(mg);
  const PhaseWork one = ch10::v_cycle_work({levels.front()}, 1, sizeof(float),
                                           stepper.arithmetic() == ch12::Arithmetic::single)
                            .parts.front();
  KernelAlone k =
      kernel("fine smoothing step (float)", one.phase, one, passes * ch10::smoother_products(mg));
  k.work.phase = "smoothing step";
  auto& fine = cycle.fine_level();
  const int step = std::min(1, ch10::smoothing_steps(fine) - 1);
  k.run = [&fine, step] {
    ch09::for_parts(source_level(fine).rows.part, true, [&](int first, int last) {
      ch10::smooth(fine, step, first, last, fine.vectors.b, &fine.vectors.x, fine.vectors.y, true);
    });
  };
  return k;
}

// The fine level's smoothing step of a chapter-12 stepper, if its hierarchy has levels below.
void add_smoothing(ch12::HalfBytesStepper& stepper, double passes,
                   std::vector<KernelAlone>& kernels) {
  if (stepper.multigrid().levels() < 2) return;
  if (auto* single = dynamic_cast<ch12::ReducedVCycle<float>*>(&stepper.v_cycle()))
    kernels.push_back(smoothing_kernel(stepper, *single, passes));
  else if (auto* wide = dynamic_cast<ch12::ReducedVCycle<double>*>(&stepper.v_cycle()))
    kernels.push_back(smoothing_kernel(stepper, *wide, passes));
}

}  // namespace

std::vector<KernelAlone> solve_kernels(Stepper& stepper, const Scene& scene, double iterations) {
  // The kernels write the stepper's work vectors (the float levels'): the caller's own
  // stepper, not one it steps on.
  auto* threads = dynamic_cast<ch09::ThreadsStepper*>(&const_cast<Stepper&>(unwrapped(stepper)));
  if (!threads) return {};
  const double passes = iterations + 1.0;
  std::vector<KernelAlone> kernels = pcg_kernels(*threads, passes);
  if (auto* half = dynamic_cast<ch12::HalfBytesStepper*>(threads))
    add_smoothing(*half, passes, kernels);
  else if (!dynamic_cast<ch10::MultigridStepper*>(threads))
    kernels.push_back(block_jacobi_kernel(*threads, scene, passes));
  return kernels;
}

double best_call_seconds(int threads, const std::function<void()>& kernel) {
  using Clock = std::chrono::steady_clock;
  const ThreadCountScope team(threads);
  double best = std::numeric_limits<double>::infinity();
  int calls = 1;
  for (int timed = 0; timed < kTimings;) {
    const Clock::time_point start = Clock::now();
    ch09::run_parallel([&] {
      for (int i = 0; i < calls; ++i) kernel();
    });
    const double t = std::chrono::duration<double>(Clock::now() - start).count();
    if (t < kMinTiming && calls < (1 << 24)) {
      calls *= 2;  // the first timings also bring the data into the cache
      continue;
    }
    best = std::min(best, t / calls);
    ++timed;
  }
  return best;
}

namespace {

const PlacedRun* placed(const std::vector<PlacedRun>& runs, const std::string& chapter,
                        const std::string& mesh, int threads) {
  for (const PlacedRun& r : runs)
    if (r.chapter == chapter && r.mesh == mesh && r.threads == threads) return &r;
  return nullptr;
}

// The placed solve, and the bound of the parts the kernels make up.
void set_solve(AloneRun& out, const Roofs& roofs, const PlacedRun& run) {
  for (const PhasePoint& p : run.phases) {
    if (p.work.phase != "solve") continue;
    out.solve_s = p.measured_s;
    out.waiting_s = p.waiting_s;
    out.solve_bound_s = p.bound_s;
    for (const PhaseWork& part : p.work.parts)
      if (std::any_of(out.kernels.begin(), out.kernels.end(),
                      [&](const KernelAlone& k) { return k.part == part.phase; }))
        out.parts_bound_s += bound_seconds(roofs, part);
  }
}

AloneRun measure_alone(const ChapterInfo& chapter, const Scene& scene, const Roofs& roofs,
                       const PlacedRun& run) {
  AloneRun out;
  out.chapter = chapter.id;
  out.mesh = run.mesh;
  out.threads = roofs.threads;
  const ThreadCountScope team(roofs.threads);
  std::unique_ptr<Stepper> stepper = chapter.make(scene, SolverSettings{});
  State state = rest_state(scene);
  for (int k = 0; k < kSteps; ++k) stepper->step(state);
  out.kernels = solve_kernels(*stepper, scene, run.iterations);
  for (KernelAlone& k : out.kernels) {
    k.bound_s = bound_seconds(roofs, k.work);
    k.seconds = best_call_seconds(roofs.threads, k.run);
    out.alone_s += k.calls * k.seconds;
  }
  set_solve(out, roofs, run);
  return out;
}

}  // namespace

std::vector<AloneRun> kernels_alone(const std::vector<const ChapterInfo*>& chapters,
                                    const Scene& scene, const std::vector<Roofs>& roofs,
                                    const std::vector<PlacedRun>& runs) {
  std::vector<AloneRun> out;
  for (const ChapterInfo* c : chapters) {
    const ChapterInfo& chapter = *c;
    for (const Roofs& r : roofs) {
      const PlacedRun* run = placed(runs, chapter.id, mesh_name(scene), r.threads);
      if (!run || run->phases.empty()) continue;  // not placed at this count, or not counted
      progress("roofline: " + chapter.id + "'s kernels alone at " + std::to_string(r.threads) +
               " thread(s)");
      out.push_back(measure_alone(chapter, scene, r, *run));
    }
  }
  return out;
}

}  // namespace fem::roofline
