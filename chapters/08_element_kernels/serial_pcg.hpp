// Chapter 08's serial PCG: chapter 07's loop with its product and its preconditioner as parts: the
// same loop, the same stopping rule and PPCG filter, but q = A p and s = M r are whatever the
// recipe names, through the two faces of contract.hpp. With chapter 08's AssembledProduct and
// BlockJacobi it runs chapter 07's arithmetic, operation for operation: the same bits as
// ch07::pcg_solve.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "chapters/08_element_kernels/contract.hpp"
#include "common/stepper.hpp"

namespace fem::ch08 {

// The work vectors of the PCG, sized on the first solve and reused afterwards.
struct PcgVectors {
  Eigen::VectorXd residual, preconditioned, direction, product;
};

// Preconditioned CG on the filtered system A y = b, on one thread. y holds the initial guess on
// entry and the solution on exit. Both parts are prepared here, once per solve.
SolveStats serial_pcg(const BlockSparseMatrix& A, ProductPart& product,
                      PreconditionerPart& preconditioner, const Eigen::VectorXd& b,
                      const std::vector<NodeConstraint>& constraints,
                      const SolverSettings& settings, PcgVectors& vectors, Eigen::VectorXd& y);

}  // namespace fem::ch08
