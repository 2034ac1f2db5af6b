// This chapter's work per phase (chapters/work.hpp: the model), and the counts of the data
// model it sets up, which the chapters that keep it count with: Eigen's compressed sparse
// matrices, common/'s element loop with its 12x12 K0, and Eigen's Jacobi-preconditioned CG.
#pragma once

#include <Eigen/SparseCore>
#include <vector>

#include "chapters/01_naive/stepper.hpp"
#include "chapters/work.hpp"

namespace fem::ch01 {

std::vector<PhaseWork> count_work(const NaiveStepper& stepper, const Scene& scene,
                                  const WorkCounts& counts);

// ---- the counts the phases are made of -------------------------------------------------

struct MeshSizes {
  double nodes, elements, dofs, vector_bytes;  // vector_bytes: one 3N vector of doubles
};
MeshSizes mesh_sizes(const Scene& scene);

// A phase's work from its parts: a write of `allocated` bytes to lines it did not read.
PhaseWork phase_work(const char* name, double read, double written, double allocated, double flops,
                     double working_set);

// Values and indices of a compressed sparse matrix (Eigen's CSC: value, inner index per
// entry, outer index per column plus one).
double matrix_bytes(const Eigen::SparseMatrix<double>& m);

// A PCG solve: the initial residual's product and `iterations` iterations, each a product
// (the matrix and p read, q written), the preconditioner (r read, z written) and the vector
// updates x += a p, r -= a q, p = z + b p (each reads two vectors and writes one it read);
// the dot products ride on those passes. Its parts: the product and updates on the matrix
// and the five vectors x, r, p, q, z; the preconditioner on its data, r and z (or, if it is
// made of parts, each of them).
PhaseWork pcg_work(const MeshSizes& m, double iterations, double matrix, double matrix_flops,
                   const PhaseWork& preconditioner);
// The same with the PCG's own kernels counted by the caller (another form of the iteration).
PhaseWork pcg_work(const MeshSizes& m, double iterations, const PhaseWork& own,
                   const PhaseWork& preconditioner);

// The steppers on Eigen's compressed matrices: df/dx and A from common/'s element loop, the
// constraints as sparse products S A S^T into a second matrix (`in_place` false) or on the
// constrained rows and columns only (true), Jacobi-preconditioned CG.
std::vector<PhaseWork> compressed_work(const Eigen::SparseMatrix<double>& dfdx,
                                       const Eigen::SparseMatrix<double>& A, const Scene& scene,
                                       const WorkCounts& counts, bool in_place);

// common/'s element loop (forces, rotations) and its blocks R K0 R^T of df/dx, whose model
// the chapters keep until the fused element pass replaces it.
PhaseWork reference_forces(const MeshSizes& m);
PhaseWork reference_dfdx(const MeshSizes& m, double matrix);

// Flops of the small products the element counts are made of (a multiply or an add is one):
// a 3x3 matrix times a 3x3 matrix, 27 multiplies and 18 adds; times a 3-vector, 9 and 6.
constexpr double kMatMat3Flops = 45.0;
constexpr double kMatVec3Flops = 15.0;

// Flops of one element, term by term.
double reference_force_flops();  // the rotation and element force of common/model.cpp
double reference_block_flops();  // the 16 blocks R K0 R^T of common/element.cpp

}  // namespace fem::ch01
