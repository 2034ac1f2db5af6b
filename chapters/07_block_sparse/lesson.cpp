// Chapter 07's lesson table: `fem_lessons spmv` (SpMV by Eigen (both storage orders) and by 3x3
// blocks (full and symmetric storage), and block Jacobi against scalar Jacobi in the PCG).
#include "chapters/07_block_sparse/lesson.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <iomanip>
#include <memory>
#include <sstream>
#include <string>

#include "chapters/06_custom_pcg/stepper.hpp"
#include "chapters/07_block_sparse/block_sparse.hpp"
#include "chapters/07_block_sparse/stepper.hpp"
#include "common/lesson.hpp"

namespace fem::ch07 {

void multiply_upper(const BlockSparseMatrix& A, const Eigen::VectorXd& x, Eigen::VectorXd& y) {
  y.setZero();
  for (int i = 0; i < A.block_rows(); ++i) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    const Eigen::Vector3d xi = x.segment<3>(3 * i);
    for (int k = A.row_start[i]; k < A.row_start[i + 1]; ++k) {
      const int j = A.column[k];
      if (j < i) continue;  // only the upper blocks are read
      sum.noalias() += A.blocks[k] * x.segment<3>(3 * j);
      if (j != i) y.segment<3>(3 * j).noalias() += A.blocks[k].transpose() * xi;
    }
    y.segment<3>(3 * i) += sum;
  }
}

BlockSparseMatrix upper(const BlockSparseMatrix& A) {
  BlockSparseMatrix u;
  for (int i = 0; i < A.block_rows(); ++i) {
    for (int k = A.row_start[i]; k < A.row_start[i + 1]; ++k) {
      if (A.column[k] < i) continue;
      u.column.push_back(A.column[k]);
      u.blocks.push_back(A.blocks[k]);
    }
    u.row_start.push_back(static_cast<int>(u.column.size()));
  }
  return u;
}

namespace {

// One row of the SpMV table: its median time against Eigen's column-major product.
std::string spmv_row(const std::string& what, double ms, double reference_ms, double index_kib) {
  std::ostringstream row;
  row << std::fixed << "| " << what << " | " << std::setprecision(4) << ms << " | "
      << std::setprecision(2) << reference_ms / ms << "x | " << std::setprecision(0) << index_kib
      << " |\n";
  return row.str();
}

// y = A x by Eigen's three products and by the blocks, full and symmetric storage.
std::string spmv_rows(const BlockSparseMatrix& A, const Eigen::SparseMatrix<double>& csc,
                      int repeat) {
  const BlockSparseMatrix upper_A = upper(A);
  const Eigen::VectorXd x = Eigen::VectorXd::Ones(csc.cols());
  Eigen::VectorXd y(x.size());
  progress("SpMV, five formats, " + std::to_string(repeat) + " runs or 10 s each");
  const double eigen_col = time_ms(repeat, [&] { y.noalias() = csc * x; });
  const double eigen_row = time_ms(repeat, [&] { y.noalias() = csc.transpose() * x; });
  const double eigen_lower =
      time_ms(repeat, [&] { y.noalias() = csc.selfadjointView<Eigen::Lower>() * x; });
  const double block_full = time_ms(repeat, [&] { A.multiply(x, y); });
  const double block_upper = time_ms(repeat, [&] { multiply_upper(upper_A, x, y); });
  // Index memory: CSC stores one row index per entry and one pointer per column; BSR one
  // column index per block and one pointer per block row.
  const auto kib = [](std::size_t ints) {
    return static_cast<double>(ints * sizeof(int)) / 1024.0;
  };
  const double csc_kib = kib(csc.nonZeros() + csc.cols() + 1);
  return "| SpMV, y = A x | median ms | vs Eigen column-major | index memory (KiB) |\n"
         "| --- | ---: | ---: | ---: |\n" +
         spmv_row("Eigen CSC, `A * x` (column scatter)", eigen_col, eigen_col, csc_kib) +
         spmv_row("Eigen CSC, `A.transpose() * x` (row gather, chapter 06)", eigen_row, eigen_col,
                  csc_kib) +
         spmv_row("Eigen CSC, `selfadjointView<Lower>() * x` (what `ConjugateGradient` uses)",
                  eigen_lower, eigen_col, csc_kib) +
         spmv_row("3x3 blocks, full storage (chapter 07)", block_full, eigen_col,
                  kib(A.blocks.size() + A.row_start.size())) +
         spmv_row("3x3 blocks, symmetric (upper) storage", block_upper, eigen_col,
                  kib(upper_A.blocks.size() + upper_A.row_start.size()));
}

// The PCG on the same system from zero: scalar Jacobi (chapter 06, on the CSC copy) and block
// Jacobi (chapter 07).
std::string pcg_rows(const BlockSparseStepper& stepper, const Eigen::SparseMatrix<double>& csc,
                     const Scene& scene, int steps) {
  const Eigen::VectorXd& b = stepper.system_rhs();
  const std::vector<int> offsets = ch06::diagonal_offsets(csc);
  const SolverSettings settings;
  ch06::PcgWorkspace work6;
  PcgWorkspace work7;
  Eigen::VectorXd y6, y7;
  SolveStats r6, r7;
  progress("PCG from zero, scalar and block Jacobi, " + std::to_string(steps) +
           " solves or 10 s each");
  const double pcg6 = time_ms(steps, [&] {
    y6.setZero(b.size());
    r6 = ch06::pcg_solve(csc, b, scene.constraints, offsets, settings, work6, y6);
  });
  const double pcg7 = time_ms(steps, [&] {
    y7.setZero(b.size());
    r7 = pcg_solve(stepper.system_matrix(), stepper.diagonal_blocks(), b, scene.constraints,
                   settings, work7, y7);
  });
  std::ostringstream out;
  out << std::fixed << std::setprecision(3)
      << "| PCG from zero, same system and tolerance | median ms | iterations |\n"
      << "| --- | ---: | ---: |\n"
      << "| scalar Jacobi on CSC (chapter 06) | " << pcg6 << " | " << r6.iterations << " |\n"
      << "| block Jacobi on 3x3 blocks (chapter 07) | " << pcg7 << " | " << r7.iterations << " |\n";
  return out.str();
}

std::string spmv_table(const Scene& scene, int steps) {
  BlockSparseStepper stepper(scene, {});
  State state = rest_state(scene);
  // A real, filtered system: a few steps in, the body moving. Each costs a full solve, which
  // on a large mesh takes seconds, so a few only.
  constexpr int kSetupSteps = 3;
  progress(std::to_string(kSetupSteps) + " steps of chapter 07 for a real, filtered system");
  for (int k = 0; k < kSetupSteps; ++k) stepper.step(state);
  const BlockSparseMatrix& A = stepper.system_matrix();
  const Eigen::SparseMatrix<double> csc = A.to_sparse();
  std::ostringstream out;
  out << spmv_rows(A, csc, 20 * steps) << "\n"
      << pcg_rows(stepper, csc, scene, steps) << "\n"
      << "The filtered system of step " << kSetupSteps << " of the " << scene.name << " scene on "
      << mesh_name(scene) << " (" << scene.mesh.num_nodes() << " nodes, " << csc.nonZeros()
      << " non-zeros, " << A.blocks.size() << " blocks); " << measured_on()
      << ". Generated by `fem_lessons spmv`.\n";
  return out.str();
}

}  // namespace

std::vector<Lesson> lessons() {
  return {{"spmv", "SpMV: Eigen against 3x3 blocks; PCG: scalar against block Jacobi",
           "meshes/plate_poster.msh", nullptr,
           [](const LessonRun& run) { return spmv_table(run.scene, run.steps); }}};
}

}  // namespace fem::ch07
