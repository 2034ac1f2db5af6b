#include "chapters/01_naive/work.hpp"

#include "common/element.hpp"

namespace fem::ch01 {

namespace {

constexpr double kDouble = sizeof(double);
constexpr double kBlock = 9 * kDouble;  // a 3x3 block of doubles
// A constrained block S_i a_ij S_j: two 3x3 products.
constexpr double kConstraintBlockFlops = 2 * kMatMat3Flops;
// One Newton step of the polar decomposition, R <- (R + R^-T) / 2: the cofactors (27), the
// determinant from them (5), its inverse and the scaling (10), the average (18). The SVD this
// chapter runs does more; what it does beyond this step is distance from the bound.
constexpr double kPolarStepFlops = 60.0;

// Stored entries in the columns of the constrained nodes' dofs (= in their rows: A is
// symmetric).
double constrained_entries(const Eigen::SparseMatrix<double>& A, const Scene& scene) {
  double entries = 0;
  for (const NodeConstraint& c : scene.constraints)
    for (int d = 0; d < 3; ++d)
      entries += A.outerIndexPtr()[3 * c.node + d + 1] - A.outerIndexPtr()[3 * c.node + d];
  return entries;
}

// A = (1 + h alpha) M - (h beta + h^2) df/dx and b = h (f + df/dx (h + beta) v + ...): df/dx
// read, A written (a fresh matrix), an FMA per entry and a product with df/dx; M, v, f and
// f_ext read, b written.
PhaseWork reference_compose(const MeshSizes& m, double dfdx, double A, double entries) {
  return phase_work("compose", dfdx + 4 * m.vector_bytes, A + m.vector_bytes, A + m.vector_bytes,
                    4 * entries + 6 * m.dofs, dfdx + A + 5 * m.vector_bytes);
}

}  // namespace

MeshSizes mesh_sizes(const Scene& scene) {
  const double nodes = scene.mesh.num_nodes();
  return {nodes, double(scene.mesh.num_tets()), 3 * nodes, 3 * nodes * kDouble};
}

PhaseWork phase_work(const char* name, double read, double written, double allocated, double flops,
                     double working_set) {
  PhaseWork w;
  w.phase = name;
  w.bytes_read = read;
  w.bytes_written = written;
  w.bytes_allocated = allocated;
  w.flops_double = flops;
  w.working_set = working_set;
  return w;
}

double matrix_bytes(const Eigen::SparseMatrix<double>& m) {
  using Index = Eigen::SparseMatrix<double>::StorageIndex;
  return double(m.nonZeros()) * (sizeof(double) + sizeof(Index)) +
         double(m.outerSize() + 1) * sizeof(Index);
}

PhaseWork pcg_work(const MeshSizes& m, double iterations, double matrix, double matrix_flops,
                   const PhaseWork& preconditioner) {
  const double v = m.vector_bytes;
  // The PCG's own kernels: the product (the matrix and p read, q written fresh) and the
  // updates (two vectors read each, x, r and p written back).
  const PhaseWork own = phase_work("pcg", matrix + v + 3 * 2 * v, v + 3 * v, v,
                                   matrix_flops + 10 * m.dofs, matrix + 5 * v);
  return pcg_work(m, iterations, own, preconditioner);
}

PhaseWork pcg_work(const MeshSizes& m, double iterations, const PhaseWork& own,
                   const PhaseWork& preconditioner) {
  const double passes = iterations + 1.0;
  const double v = m.vector_bytes;
  // The preconditioner reads r and writes z (fresh lines) besides its own data; a
  // preconditioner made of kernels (a V-cycle) keeps them, each at its own level.
  PhaseWork apply = phase_work("preconditioner", v, v, v, 0.0, 2 * v);
  if (preconditioner.parts.empty()) {
    apply.bytes_read += preconditioner.bytes_read;
    apply.bytes_written += preconditioner.bytes_written;
    apply.bytes_allocated += preconditioner.bytes_allocated;
    apply.flops_double = preconditioner.flops_double;
    apply.flops_float = preconditioner.flops_float;
    apply.working_set += preconditioner.working_set;
  }
  PhaseWork w =
      phase_work("solve", 0.0, 0.0, 0.0, 0.0, own.working_set + preconditioner.working_set);
  w.add_part(own, passes);
  w.add_part(apply, passes);
  if (!preconditioner.parts.empty()) w.add_part(preconditioner, passes);
  return w;
}

PhaseWork reference_forces(const MeshSizes& m) {
  // Reads each element's whole ElementRest (Dm^-1, volume, K0, X_e: common/element.hpp), its
  // corners, x and gravity; writes R_e and f.
  const double read =
      m.elements * (sizeof(ElementRest) + sizeof(Eigen::Vector4i)) + 2 * m.vector_bytes;
  const double written = m.elements * kBlock + m.vector_bytes;
  return phase_work("forces", read, written, written, m.elements * reference_force_flops(),
                    read + written);
}

PhaseWork reference_dfdx(const MeshSizes& m, double matrix) {
  // Per element K0, R_e and its corners read; the matrix written once, its indices read to
  // find where each block goes.
  const double read = m.elements * (sizeof(Matrix12d) + kBlock + sizeof(Eigen::Vector4i));
  return phase_work("dfdx", read, matrix, matrix, m.elements * reference_block_flops(),
                    read + matrix);
}

std::vector<PhaseWork> compressed_work(const Eigen::SparseMatrix<double>& dfdx,
                                       const Eigen::SparseMatrix<double>& A, const Scene& scene,
                                       const WorkCounts& counts, bool in_place) {
  const MeshSizes m = mesh_sizes(scene);
  const double matrix = matrix_bytes(A), entries = double(A.nonZeros());
  const double v = m.vector_bytes;
  // In place: the constrained rows and columns read and written back. Else S A S^T into a
  // second matrix: df/dx's pattern and A read, the filtered matrix written fresh.
  const double constrained = constrained_entries(A, scene);
  const double touched = 2 * constrained * kDouble;  // their rows and their columns
  const double flops = 2 * kConstraintBlockFlops * constrained / 9;
  const PhaseWork constraints =
      in_place ? phase_work("constraints", touched + 2 * v, touched + v, v, flops, touched + 3 * v)
               : phase_work("constraints", matrix_bytes(dfdx) + 2 * v, matrix + v, matrix + v,
                            flops, matrix_bytes(dfdx) + matrix + 3 * v);
  // Jacobi: the inverse diagonal and r read, z written (its bytes are pcg_work's).
  const PhaseWork jacobi = phase_work("jacobi", v, 0.0, 0.0, m.dofs, v);
  return {reference_forces(m), reference_dfdx(m, matrix_bytes(dfdx)),
          reference_compose(m, matrix_bytes(dfdx), matrix, entries), constraints,
          pcg_work(m, counts.cg_iterations, matrix, 2 * entries, jacobi)};
}

std::vector<PhaseWork> count_work(const NaiveStepper& stepper, const Scene& scene,
                                  const WorkCounts& counts) {
  return compressed_work(stepper.dfdx(), stepper.system_matrix(), scene, counts, false);
}

double reference_force_flops() {
  // common/model.cpp compute_rotations_and_forces: f_e = -R K0 (R^T x_e - X_e), then f += f_e.
  const double deformation = 9.0 + kMatMat3Flops;   // Ds, F = Ds Dm^-1
  const double local = 4.0 * kMatVec3Flops + 12.0;  // R^T x_a for 4 corners, minus X_e
  const double stiffness = 144.0 + 132.0;           // K0 (12 x 12) times a 12-vector
  const double rotate = 4.0 * kMatVec3Flops;        // R times the 4 corner forces
  return deformation + kPolarStepFlops + local + stiffness + rotate + 12.0;
}

double reference_block_flops() {
  // common/element.cpp: the 16 blocks R K0_ab R^T, each two 3x3 products, added into df/dx.
  return 16.0 * (2.0 * kMatMat3Flops + 9.0);
}

}  // namespace fem::ch01
