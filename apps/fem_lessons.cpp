// fem_lessons: the measurements behind individual lessons, printed as Markdown tables
// (and, with --readme, written between marker comments of a chapter's README, so that
// no number in a lesson is typed by hand).
//   noalias    chapter 02: heap allocations of each vector statement, before and after
//   dfdx-fill  chapter 03: df/dx construction by coeffRef, by setFromTriplets, by the table
//   compose    chapter 04: the heap allocations of chapter 03's sparse sums, cause by cause
//   spmv       chapter 07: SpMV by Eigen (both storage orders) and by 3x3 blocks (full and
//              symmetric storage), and block Jacobi against scalar Jacobi in the PCG
//   rotations  chapter 08: per element, the rotation by JacobiSVD and by Newton (cold and
//              warm-started), the element blocks from a stored K0 and in closed form
//   threads-element  chapter 09: the fused element pass in parallel by colouring and by
//              per-node gather, on one thread and on all of them
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "chapters/02_noalias/statements.hpp"
#include "chapters/06_custom_pcg/stepper.hpp"
#include "chapters/07_block_sparse/stepper.hpp"
#include "chapters/08_element_kernels/stepper.hpp"
#include "chapters/09_threads/parallel.hpp"
#include "chapters/09_threads/stepper.hpp"
#include "chapters/registry.hpp"
#include "common/alloc_counter.hpp"
#include "common/build_info.hpp"
#include "common/cli.hpp"
#include "common/model.hpp"
#include "common/threads.hpp"

namespace {

using namespace fem;

std::string code(const std::string& s) {
  std::string out = "`";
  for (const char c : s) out += (c == '|') ? '/' : c;  // keep Markdown table cells intact
  return out + "`";
}

std::string noalias_table(const Scene& scene) {
  std::ostringstream out;
  out << "| chapter 01 statement | allocations | chapter 02 rewrite | allocations |\n"
      << "| --- | ---: | --- | ---: |\n";
  for (const auto& c : ch02::count_statements(scene))
    out << "| " << code(c.before_code) << " | " << c.before << " | " << code(c.after_code) << " | "
        << c.after << " |\n";
  return out.str();
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// The third way to fill df/dx: collect triplets and rebuild the matrix every step.
double set_from_triplets_ms(const Scene& scene, int steps) {
  const Model model(scene);
  std::vector<Eigen::Matrix3d> rotations(model.tets.size());
  Eigen::VectorXd f(model.dofs);
  State state = rest_state(scene);
  compute_rotations_and_forces(model, state.x, rotations, f);
  Eigen::SparseMatrix<double> dfdx(model.dofs, model.dofs);
  std::vector<Eigen::Triplet<double>> triplets;
  std::vector<double> ms;
  for (int k = 0; k < steps; ++k) {
    const auto start = std::chrono::steady_clock::now();
    triplets.clear();
    for (std::size_t e = 0; e < model.tets.size(); ++e) {
      const Eigen::Vector4i& t = model.tets[e];
      for (int a = 0; a < 4; ++a)
        for (int b = 0; b < 4; ++b) {
          const Eigen::Matrix3d block = dfdx_block(model.rest[e], rotations[e], a, b);
          for (int c = 0; c < 3; ++c)
            for (int r = 0; r < 3; ++r)
              triplets.emplace_back(3 * t[a] + r, 3 * t[b] + c, block(r, c));
        }
    }
    dfdx.setFromTriplets(triplets.begin(), triplets.end());  // sorts, sums duplicates, allocates
    ms.push_back(1e3 *
                 std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  return median(ms);
}

double dfdx_phase_ms(const std::string& chapter, const Scene& scene, int steps) {
  auto stepper = make_stepper(chapter, scene, {});
  State state = rest_state(scene);
  std::vector<double> ms;
  for (int k = 0; k < steps; ++k) {
    stepper->step(state);
    ms.push_back(1e3 * stepper->profile().dfdx.seconds);
  }
  return median(ms);
}

std::string dfdx_fill_table(const Scene& scene, int steps) {
  const double coeff_ref = dfdx_phase_ms("02", scene, steps);
  const double triplets = set_from_triplets_ms(scene, steps);
  const double table = dfdx_phase_ms("03", scene, steps);
  const BuildInfo b = build_info();
  std::ostringstream out;
  out << std::fixed << std::setprecision(3);
  out << "| df/dx construction | median ms | vs coeffRef |\n| --- | ---: | ---: |\n"
      << "| `coeffRef` per entry (chapters 01, 02) | " << coeff_ref << " | 1.00x |\n"
      << "| `setFromTriplets` every step | " << triplets << " | " << std::setprecision(2)
      << coeff_ref / triplets << "x |\n"
      << std::setprecision(3) << "| offset table (chapter 03) | " << table << " | "
      << std::setprecision(2) << coeff_ref / table << "x |\n\n"
      << "Median of " << steps << " steps, " << scene.name << " scene on "
      << std::filesystem::path(scene.mesh.file).filename().string() << " ("
      << scene.mesh.num_nodes() << " nodes, " << scene.mesh.num_tets() << " tets); " << cpu_model()
      << ", " << b.compiler << ", `" << b.flags << "`. Generated by `fem_lessons dfdx-fill`.\n";
  return out.str();
}

// How Eigen 3.4 evaluates `dst = sparse expression` (assign_sparse_to_sparse in
// SparseCore/SparseAssign.h): the expression is not an rvalue, so it is evaluated lazily, in
// one pass, into one temporary whose outer index is malloc'ed in resize(), whose value and
// index arrays start from reserve(2 max(rows, cols)) and grow by append(), i.e.
// CompressedStorage::resize(size + 1, 1), which reallocates both arrays to twice the size
// (CompressedStorage.h); the temporary is then swapped into dst. Returns the allocations
// this predicts for a result with nnz non-zeros: 1 + 2 per reallocation.
long long predicted_sparse_assign_allocations(Eigen::Index n, Eigen::Index nnz,
                                              int& reallocations) {
  Eigen::Index capacity = 2 * n;
  reallocations = 1;  // the reserve
  while (capacity < nnz) {
    capacity = 2 * (capacity + 1);
    ++reallocations;
  }
  return 1 + 2LL * reallocations;
}

std::string compose_table(const Scene& scene) {
  // Chapter 03's composition, statement by statement, with the matrices of a real step.
  ch01::NaiveStepper naive(scene, {});
  State state = rest_state(scene);
  naive.step(state);
  const Eigen::SparseMatrix<double>& dfdx = naive.dfdx();
  const Eigen::Index n = dfdx.rows();
  Eigen::SparseMatrix<double> M(n, n);
  M.setIdentity();
  M.diagonal() = Model(scene).lumped_mass;
  const double h = scene.dt, alpha = scene.damping.alpha, beta = scene.damping.beta;
  Eigen::SparseMatrix<double> dfdv, A = dfdx;
  alloc::Counts first, second;
  {
    alloc::Scope scope;
    const Eigen::SparseMatrix<double> sum = -alpha * M + beta * dfdx;
    first = scope.delta();
    dfdv = sum;
  }
  {
    alloc::Scope scope;
    A = M - h * dfdv - h * h * dfdx;
    second = scope.delta();
  }
  std::ostringstream out;
  out << "| chapter 03 statement | non-zeros | allocations (of them `new[]`) | reallocations "
         "of the temporary | predicted: 1 + 2 x reallocations |\n"
      << "| --- | ---: | ---: | ---: | ---: |\n";
  const auto row = [&](const char* statement, Eigen::Index nnz, const alloc::Counts& c) {
    int reallocations = 0;
    const long long predicted = predicted_sparse_assign_allocations(n, nnz, reallocations);
    out << "| `" << statement << "` | " << nnz << " | " << c.allocations << " (" << c.new_calls
        << ") | " << reallocations << " | " << predicted << " |\n";
  };
  row("const SparseMatrix dfdv = -alpha * M_ + beta * dfdx_", dfdv.nonZeros(), first);
  row("A_ = M_ - h * dfdv - h * h * dfdx_", A.nonZeros(), second);
  out << "\n" << scene.name << " scene on "
      << std::filesystem::path(scene.mesh.file).filename().string() << " (" << n
      << " dofs). A two-term and a three-term sum allocate alike: no matrix per `+`. "
         "Generated by `fem_lessons compose`.\n";
  return out.str();
}

// Median milliseconds of f, run `repeat` times but stopped once `budget_s` seconds are spent
// (after one run at least): a lesson on a large mesh finishes in bounded time.
template <class F>
double time_ms(int repeat, F&& f, double budget_s = 10.0) {
  std::vector<double> ms;
  double spent = 0.0;
  for (int k = 0; k < repeat && (k == 0 || spent < budget_s); ++k) {
    const auto start = std::chrono::steady_clock::now();
    f();
    ms.push_back(1e3 *
                 std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    spent += 1e-3 * ms.back();
  }
  return median(ms);
}

// Progress of a long lesson, on stderr so that stdout stays the Markdown table.
void progress(const std::string& what) {
  std::cerr << "  fem_lessons: " << what << "\n" << std::flush;
}

std::string spmv_table(const Scene& scene, int steps) {
  ch07::BlockSparseStepper stepper(scene, {});
  State state = rest_state(scene);
  // A real, filtered system: a few steps in, the body moving. Each costs a full solve, which
  // on a large mesh takes seconds, so a few only.
  constexpr int kSetupSteps = 3;
  progress(std::to_string(kSetupSteps) + " steps of chapter 07 for a real, filtered system");
  for (int k = 0; k < kSetupSteps; ++k) stepper.step(state);
  const ch07::BlockSparseMatrix& A = stepper.system_matrix();
  const ch07::BlockSparseMatrix upper = A.upper();
  const Eigen::SparseMatrix<double> csc = A.to_sparse();
  const Eigen::VectorXd x = Eigen::VectorXd::Ones(csc.cols());
  Eigen::VectorXd y(x.size());
  const int repeat = 20 * steps;
  progress("SpMV, five formats, " + std::to_string(repeat) + " runs or 10 s each");
  const double eigen_col = time_ms(repeat, [&] { y.noalias() = csc * x; });
  const double eigen_row = time_ms(repeat, [&] { y.noalias() = csc.transpose() * x; });
  const double eigen_lower =
      time_ms(repeat, [&] { y.noalias() = csc.selfadjointView<Eigen::Lower>() * x; });
  const double block_full = time_ms(repeat, [&] { A.multiply(x, y); });
  const double block_upper = time_ms(repeat, [&] { upper.multiply_upper(x, y); });
  const long long nnz = csc.nonZeros();
  const std::size_t nb = A.blocks.size();
  // Index memory: CSC stores one row index per entry and one pointer per column; BSR one
  // column index per block and one pointer per block row.
  const double csc_index_kb = (nnz + csc.cols() + 1) * sizeof(int) / 1024.0;
  const double bsr_index_kb = (nb + A.row_start.size()) * sizeof(int) / 1024.0;

  // The PCG on the same system: scalar Jacobi (chapter 06, on the CSC copy) and block
  // Jacobi (chapter 07).
  const Eigen::VectorXd& b = stepper.system_rhs();
  const std::vector<int> offsets = ch06::diagonal_offsets(csc);
  SolverSettings settings;
  ch06::PcgWorkspace work6;
  ch07::PcgWorkspace work7;
  Eigen::VectorXd y6, y7;
  ch06::PcgResult r6;
  ch07::PcgResult r7;
  progress("PCG from zero, scalar and block Jacobi, " + std::to_string(steps) +
           " solves or 10 s each");
  const double pcg6 = time_ms(steps, [&] {
    y6.setZero(b.size());
    r6 = ch06::pcg_solve(csc, b, scene.constraints, offsets, settings, work6, y6);
  });
  const double pcg7 = time_ms(steps, [&] {
    y7.setZero(b.size());
    r7 = ch07::pcg_solve(A, stepper.diagonal_blocks(), b, scene.constraints, settings, work7, y7);
  });

  const BuildInfo info = build_info();
  std::ostringstream out;
  out << std::fixed << std::setprecision(4);
  out << "| SpMV, y = A x | median ms | vs Eigen column-major | index memory (KiB) |\n"
      << "| --- | ---: | ---: | ---: |\n"
      << "| Eigen CSC, `A * x` (column scatter) | " << eigen_col << " | 1.00x | "
      << std::setprecision(0) << csc_index_kb << " |\n"
      << std::setprecision(4) << "| Eigen CSC, `A.transpose() * x` (row gather, chapter 06) | "
      << eigen_row << " | " << std::setprecision(2) << eigen_col / eigen_row << "x | "
      << std::setprecision(0) << csc_index_kb << " |\n"
      << std::setprecision(4)
      << "| Eigen CSC, `selfadjointView<Lower>() * x` (what `ConjugateGradient` uses) | "
      << eigen_lower << " | " << std::setprecision(2) << eigen_col / eigen_lower << "x | "
      << std::setprecision(0) << csc_index_kb << " |\n"
      << std::setprecision(4) << "| 3x3 blocks, full storage (chapter 07) | " << block_full << " | "
      << std::setprecision(2) << eigen_col / block_full << "x | " << std::setprecision(0)
      << bsr_index_kb << " |\n"
      << std::setprecision(4) << "| 3x3 blocks, symmetric (upper) storage | " << block_upper
      << " | " << std::setprecision(2) << eigen_col / block_upper << "x | " << std::setprecision(0)
      << (upper.blocks.size() + upper.row_start.size()) * sizeof(int) / 1024.0 << " |\n\n";
  out << "| PCG from zero, same system and tolerance | median ms | iterations |\n"
      << "| --- | ---: | ---: |\n"
      << std::setprecision(3) << "| scalar Jacobi on CSC (chapter 06) | " << pcg6 << " | "
      << r6.iterations << " |\n"
      << "| block Jacobi on 3x3 blocks (chapter 07) | " << pcg7 << " | " << r7.iterations
      << " |\n\n";
  out << "The filtered system of step " << kSetupSteps << " of the " << scene.name << " scene on "
      << std::filesystem::path(scene.mesh.file).filename().string() << " ("
      << scene.mesh.num_nodes() << " nodes, " << nnz << " non-zeros, " << nb << " blocks); "
      << cpu_model() << ", " << info.compiler << ", `" << info.flags
      << "`. Generated by `fem_lessons spmv`.\n";
  return out.str();
}

// The polar rotation through Eigen's closed-form 3x3 eigensolver of F^T F = V L V^T:
// R = F V L^-1/2 V^T. Fast, but it squares F's condition number and knows no inversion.
Eigen::Matrix3d polar_by_eigensolver(const Eigen::Matrix3d& F) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen;
  eigen.computeDirect(F.transpose() * F);
  const Eigen::Matrix3d& V = eigen.eigenvectors();
  return F * V * eigen.eigenvalues().cwiseSqrt().cwiseInverse().asDiagonal() * V.transpose();
}

std::string rotations_table(const Scene& bench_scene, int steps) {
  // Deformation gradients of a real step, and the rotations of the step before: the warm
  // start the stepper has.
  ch08::ElementKernelsStepper stepper(bench_scene, {});
  State state = rest_state(bench_scene);
  for (int k = 0; k < 20; ++k) stepper.step(state);
  const Model model(bench_scene);
  const std::size_t m = model.tets.size();
  std::vector<Eigen::Matrix3d> F(m), R(m);
  for (std::size_t e = 0; e < m; ++e)
    F[e] = deformation_gradient(model.rest[e], gather(state.x, model.tets[e]));
  const std::vector<Eigen::Quaterniond> previous = stepper.rotations();
  const std::vector<Eigen::Quaterniond> before = stepper.previous_rotations();
  std::vector<Eigen::Quaterniond> q(m);

  const int repeat = std::max(5, steps);
  const double to_ns = 1e6 / static_cast<double>(m);  // median ms of a sweep -> ns/element
  long long fallbacks = 0;
  // Newton's iterations summed over the elements, and the elements where it cannot decide.
  struct Count {
    long long iterations = 0, undecided = 0;
    void add(int k) { k > 0 ? iterations += k : ++undecided; }
    std::string mean(std::size_t elements) const {
      std::ostringstream s;
      s << std::fixed << std::setprecision(2)
        << static_cast<double>(iterations) / static_cast<double>(elements - undecided);
      if (undecided > 0) s << " (" << undecided << " undecided)";
      return s.str();
    }
  } count_cold, count_warm, count_predicted;
  const double svd = to_ns * time_ms(repeat, [&] {
    for (std::size_t e = 0; e < m; ++e) R[e] = polar_rotation(F[e]);
  });
  const double eigensolver = to_ns * time_ms(repeat, [&] {
    for (std::size_t e = 0; e < m; ++e) R[e] = polar_by_eigensolver(F[e]);
  });
  const double cold = to_ns * time_ms(repeat, [&] {
    count_cold = Count{};
    for (std::size_t e = 0; e < m; ++e) {
      q[e] = Eigen::Quaterniond::Identity();
      count_cold.add(ch08::newton_polar_rotation(F[e], q[e]));
    }
  });
  const double warm = to_ns * time_ms(repeat, [&] {
    count_warm = Count{};
    for (std::size_t e = 0; e < m; ++e) {
      q[e] = previous[e];
      count_warm.add(ch08::newton_polar_rotation(F[e], q[e]));
    }
  });
  const double predicted = to_ns * time_ms(repeat, [&] {
    count_predicted = Count{};
    for (std::size_t e = 0; e < m; ++e) {
      q[e] = ch08::predicted_rotation(previous[e], before[e]);
      count_predicted.add(ch08::newton_polar_rotation(F[e], q[e]));
    }
  });
  const double fast = to_ns * time_ms(repeat, [&] {
    for (std::size_t e = 0; e < m; ++e) {
      q[e] = ch08::predicted_rotation(previous[e], before[e]);
      R[e] = ch08::fast_polar_rotation(F[e], q[e], fallbacks);
    }
  });
  double difference = 0.0;  // the answers, against common/'s
  for (std::size_t e = 0; e < m; ++e)
    difference = std::max(difference, (R[e] - polar_rotation(F[e])).cwiseAbs().maxCoeff());

  // The element blocks: sixteen -R K0_ab R^T from the stored K0 (chapter 07), against the
  // ten distinct blocks in closed form from the shape gradients (chapter 08).
  std::vector<ch08::ElementShape> shapes = stepper.shapes();
  Eigen::Matrix3d sink = Eigen::Matrix3d::Zero();  // keeps the blocks from being optimized out
  const double stored = to_ns * time_ms(repeat, [&] {
    for (std::size_t e = 0; e < m; ++e)
      for (int ab = 0; ab < 16; ++ab) sink += dfdx_block(model.rest[e], R[e], ab / 4, ab % 4);
  });
  std::array<Eigen::Matrix3d, 10> K;
  const double closed = to_ns * time_ms(repeat, [&] {
    for (std::size_t e = 0; e < m; ++e) {
      ch08::stiffness_blocks(ch08::rotated_gradients(R[e], shapes[e].Dm_inv), shapes[e].mu_volume,
                             shapes[e].lambda_volume, K);
      for (const Eigen::Matrix3d& k : K) sink += k;
    }
  });

  // How often the stepper falls back to the SVD on the benchmark's scenes.
  std::ostringstream scenes;
  for (const std::string& name : scene_names()) {
    std::cerr << "fem_lessons rotations: " << steps << " steps of the " << name
              << " scene, counting SVD fallbacks\n";
    Scene scene = make_scene(name, bench_scene.mesh, bench_scene.material);
    scene.dt = bench_scene.dt;
    ch08::ElementKernelsStepper run(scene, {});
    State s = rest_state(scene);
    for (int k = 0; k < steps; ++k) run.step(s);
    scenes << (scenes.tellp() > 0 ? ", " : "") << name << " " << run.total_fallbacks() << " of "
           << static_cast<long long>(steps) * static_cast<long long>(m);
  }

  const auto mib = [m](std::size_t bytes) { return static_cast<double>(bytes * m) / (1 << 20); };
  const BuildInfo info = build_info();
  std::ostringstream out;
  out << std::fixed << std::setprecision(1);
  out << "| rotation of one element | ns per element | vs JacobiSVD | iterations |\n"
      << "| --- | ---: | ---: | ---: |\n"
      << "| `JacobiSVD<Matrix3d>`, U V^T (common/, chapters 01-07) | " << svd << " | 1.00x | - |\n"
      << "| `SelfAdjointEigenSolver::computeDirect` of F^T F (no inversion, squared condition) | "
      << eigensolver << " | " << std::setprecision(2) << svd / eigensolver << "x | - |\n"
      << std::setprecision(1) << "| Newton, cold (from the identity) | " << cold << " | "
      << std::setprecision(2) << svd / cold << "x | " << count_cold.mean(m) << " |\n"
      << std::setprecision(1) << "| Newton, warm (from the previous step's rotation) | " << warm
      << " | " << std::setprecision(2) << svd / warm << "x | " << count_warm.mean(m) << " |\n"
      << std::setprecision(1)
      << "| Newton, warm (predicted from the last two steps' rotations) | " << predicted
      << " | " << std::setprecision(2) << svd / predicted << "x | " << count_predicted.mean(m)
      << " |\n"
      << std::setprecision(1)
      << "| predicted start, Newton, SVD fallback: the stepper's (chapter 08) | " << fast
      << " | " << std::setprecision(2) << svd / fast << "x | - |\n\n";
  out << std::setprecision(1)
      << "| element blocks of -df/dx | ns per element | vs stored K0 | rest data per element "
         "(bytes) | rest data per step (MiB) |\n"
      << "| --- | ---: | ---: | ---: | ---: |\n"
      << "| sixteen `-R K0_ab R^T` from the stored K0 (chapter 07) | " << stored << " | 1.00x | "
      << sizeof(ElementRest) << " | " << std::setprecision(2) << mib(sizeof(ElementRest)) << " |\n"
      << std::setprecision(1) << "| ten closed-form blocks from the shape gradients (chapter 08) | "
      << closed << " | " << std::setprecision(2) << stored / closed << "x | "
      << sizeof(ch08::ElementShape) << " | " << mib(sizeof(ch08::ElementShape)) << " |\n\n";
  out << std::setprecision(1) << "Step 21 of the " << bench_scene.name << " scene on "
      << std::filesystem::path(bench_scene.mesh.file).filename().string() << " ("
      << bench_scene.mesh.num_tets() << " tets); median of " << repeat
      << " sweeps over all elements. Largest difference from common/'s rotation: "
      << std::scientific << std::setprecision(1) << difference << std::fixed
      << ". SVD fallbacks of the stepper over " << steps << " steps (elements x steps): "
      << scenes.str() << ". " << cpu_model() << ", " << info.compiler << ", `" << info.flags
      << "`. Generated by `fem_lessons rotations`.\n";
  volatile double keep = sink.sum();
  (void)keep;
  return out.str();
}

// The block SpMV of chapter 09's PCG (the rows in fixed chunks, a static schedule, a barrier
// after each product) on the scene's system, at each thread count, in GB/s of what one
// product must read at least: the blocks and their column indices.
std::string threads_spmv_rows(const Scene& scene, const std::vector<int>& thread_counts) {
  ch09::ThreadsStepper stepper(scene, {});
  State state = rest_state(scene);
  for (int k = 0; k < 3; ++k) stepper.step(state);
  const ch09::BlockSparseMatrix& A = stepper.system_matrix();
  const ch09::RowChunks chunks(A);
  const Eigen::VectorXd x = Eigen::VectorXd::Ones(3 * A.block_rows());
  Eigen::VectorXd y(x.size());
  const int products = 100;
  const double bytes = static_cast<double>(A.blocks.size()) * (sizeof(Eigen::Matrix3d) + sizeof(int));
  std::ostringstream out;
  out << std::fixed << "| block SpMV, " << A.blocks.size() << " blocks ("
      << std::setprecision(2) << bytes / 1e6 << " MB) | threads | us per product | GB/s | speedup |\n"
      << "| --- | ---: | ---: | ---: | ---: |\n";
  double one = 0.0;
  for (const int threads : thread_counts) {
    const ThreadCountScope scope(threads);
    const double us = 1e3 / products * time_ms(7, [&] {
      ch09::run_parallel([&] {
        for (int k = 0; k < products; ++k) {
#pragma omp for schedule(static)
          for (int c = 0; c < chunks.count(); ++c)
            A.multiply_rows(x, y, chunks.start[c], chunks.start[c + 1]);
        }
      });
    });
    if (one == 0.0) one = us;
    out << "| " << std::filesystem::path(scene.mesh.file).filename().string() << " | " << threads
        << " | " << std::setprecision(1) << us << " | " << std::setprecision(1)
        << bytes / (us * 1e3) << " | " << std::setprecision(2) << one / us << "x |\n";
  }
  return out.str();
}

// Chapter 09's two race-free element passes and chapter 08's serial one: the steppers run
// interleaved, one step each in turn, and the fused element pass (the forces phase) is timed.
std::string threads_element_table(const Scene& scene, int steps) {
  struct Run {
    std::string name;
    int threads;
    std::unique_ptr<Stepper> stepper;
    State state;
    std::vector<double> ms;
  };
  const int all = max_threads();
  std::vector<Run> runs;
  runs.push_back({"serial (chapter 08)", 1, make_stepper("08", scene), rest_state(scene), {}});
  int colours = 0;
  for (const auto& [name, how] : {std::pair{"colouring", ch09::ElementParallelism::colouring},
                                  std::pair{"per-node gather", ch09::ElementParallelism::gather}})
    for (const int threads : all > 1 ? std::vector<int>{1, all} : std::vector<int>{1}) {
      auto stepper = std::make_unique<ch09::ThreadsStepper>(scene, SolverSettings{}, how);
      colours = std::max(colours, stepper->colours());
      runs.push_back({name, threads, std::move(stepper), rest_state(scene), {}});
    }
  for (int k = 0; k < steps + 2; ++k)
    for (Run& run : runs) {
      const ThreadCountScope threads(run.threads);
      run.stepper->step(run.state);
      if (k >= 2) run.ms.push_back(1e3 * run.stepper->profile().forces.seconds);  // set-up first
    }
  const double serial = median(runs.front().ms);
  const BuildInfo info = build_info();
  std::ostringstream out;
  out << std::fixed << std::setprecision(3)
      << "| element pass | threads | median ms | vs chapter 08 |\n"
      << "| --- | ---: | ---: | ---: |\n";
  for (const Run& run : runs)
    out << "| " << run.name << " | " << run.threads << " | " << median(run.ms) << " | "
        << std::setprecision(2) << serial / median(run.ms) << "x |\n"
        << std::setprecision(3);
  out << "\n" << threads_spmv_rows(scene, all > 1 ? std::vector<int>{1, all} : std::vector<int>{1});
  out << "\nThe fused element pass (rotations, forces, blocks into A and b), median of " << steps
      << " steps of the " << scene.name << " scene on "
      << std::filesystem::path(scene.mesh.file).filename().string() << " ("
      << scene.mesh.num_tets() << " tets; " << colours << " colours of groups of 16 elements); "
      << cpu_model() << ", " << info.compiler << ", `" << info.flags
      << "`. Generated by `fem_lessons threads-element`.\n";
  return out.str();
}

// Replaces the text between <!-- NAME:begin --> and <!-- NAME:end --> in a file.
void write_between_markers(const std::string& path, const std::string& name,
                           const std::string& text) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read '" + path + "'");
  std::stringstream buffer;
  buffer << in.rdbuf();
  std::string doc = buffer.str();
  const std::string begin = "<!-- " + name + ":begin -->", end = "<!-- " + name + ":end -->";
  const auto b = doc.find(begin), e = doc.find(end);
  if (b == std::string::npos || e == std::string::npos || e < b)
    throw std::runtime_error("'" + path + "' has no markers " + begin + " ... " + end);
  doc.replace(b + begin.size(), e - b - begin.size(), "\n" + text);
  std::ofstream(path) << doc;
}

const char* const kUsage =
    "usage: fem_lessons [noalias|dfdx-fill|compose|spmv|rotations|threads-element [options]]\n"
    "  noalias    allocations of each vector statement of chapter 01 and its chapter 02 rewrite\n"
    "  dfdx-fill  df/dx construction time: coeffRef, setFromTriplets, the offset table\n"
    "  compose    allocations of chapter 03's sparse sums, measured and predicted per cause\n"
    "  spmv       SpMV: Eigen against 3x3 blocks; PCG: scalar against block Jacobi\n"
    "  rotations  per element: rotation by SVD and by Newton; blocks from K0 and closed form\n"
    "  threads-element  chapter 09's element pass: colouring against per-node gather\n"
    "without a lesson: every lesson in turn, with its defaults\n";

// One lesson with its options (argv[0] is the lesson's name); returns the exit status.
int run_lesson(const std::string& lesson, int argc, char** argv) {
  ArgParser args("fem_lessons " + lesson, "Prints the lesson's table in Markdown.");
  add_scene_options(args, lesson == "noalias" || lesson == "compose" ? "meshes/test_beam.msh"
                                                                      : "meshes/plate_poster.msh");
  args.option("steps", "N", "measured steps (dfdx-fill, rotations), solves (spmv; SpMV runs x20)",
              "50");
  args.option("readme", "FILE", "also write the table between the lesson's markers in FILE", "");
  add_thread_option(args);  // threads-element: the count beside one thread
  try {
    if (!args.parse(argc, argv)) return 0;
    threads_from_args(args);
    const Scene scene = scene_from_args(args);
    const int steps = args.get_int("steps");
    if (steps <= 0) throw UsageError("--steps must be positive");
    const std::string table = lesson == "noalias"     ? noalias_table(scene)
                              : lesson == "dfdx-fill" ? dfdx_fill_table(scene, steps)
                              : lesson == "compose"   ? compose_table(scene)
                              : lesson == "rotations" ? rotations_table(scene, steps)
                              : lesson == "threads-element" ? threads_element_table(scene, steps)
                                                      : spmv_table(scene, steps);
    std::cout << table;
    if (const std::string& readme = args.get("readme"); !readme.empty()) {
      write_between_markers(readme, lesson + "-table", table);
      std::cout << "wrote " << readme << "\n";
    }
  } catch (const UsageError& e) {
    std::cerr << "fem_lessons: " << e.what() << " (see fem_lessons " << lesson << " --help)\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "fem_lessons: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const std::vector<std::string> lessons = {"noalias", "dfdx-fill", "compose", "spmv",
                                            "rotations", "threads-element"};
  if (argc < 2) {  // every lesson, as the README of its chapter shows it
    for (const std::string& lesson : lessons) {
      std::cout << "\n## fem_lessons " << lesson << "\n\n" << std::flush;
      char* lesson_argv[] = {argv[0]};
      if (const int status = run_lesson(lesson, 1, lesson_argv); status != 0) return status;
    }
    return 0;
  }
  const std::string first = argv[1];
  if (first == "--help" || first == "-h") {
    std::cout << kUsage << "(fem_lessons LESSON --help for the options)\n";
    return 0;
  }
  if (std::find(lessons.begin(), lessons.end(), first) == lessons.end()) {
    std::cerr << "fem_lessons: unknown lesson '" << first << "'\n" << kUsage;
    return 2;
  }
  return run_lesson(first, argc - 1, argv + 1);
}
