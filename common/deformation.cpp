#include "common/deformation.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <iostream>

namespace fem {

DeformationCheck check_deformation(const TetMesh& mesh, const Eigen::VectorXd& x) {
  DeformationCheck check;
  const Eigen::Vector3d low = mesh.X.rowwise().minCoeff(), high = mesh.X.rowwise().maxCoeff();
  check.body_size = (high - low).norm();
  for (Eigen::Index i = 0; i < mesh.X.cols(); ++i)
    check.largest_move = std::max(check.largest_move, (x.segment<3>(3 * i) - mesh.X.col(i)).norm());
  for (const Eigen::Vector4i& t : mesh.tets) {
    Eigen::Matrix3d Ds;
    for (int k = 0; k < 3; ++k) Ds.col(k) = x.segment<3>(3 * t[k + 1]) - x.segment<3>(3 * t[0]);
    if (!(Ds.determinant() > 0.0)) ++check.inverted;
  }
  return check;
}

void DeformationReport::after_step(int step, const DeformationCheck& check) {
  if (!check.implausible()) return;
  if (implausible_steps_++ == 0)
    std::cerr << "warning: step " << step << " left " << check.inverted
              << " tetrahedra inverted and moved a node " << check.largest_move
              << " m (the body is " << check.body_size
              << " m across): the linearized step cannot describe this; try a smaller --dt "
                 "(reported once, counted to the end)\n";
  most_inverted_ = std::max(most_inverted_, check.inverted);
  largest_move_ = std::max(largest_move_, check.largest_move);
  body_size_ = check.body_size;
}

void DeformationReport::summary(int steps) const {
  if (implausible_steps_ == 0) return;
  std::cerr << "warning: " << implausible_steps_ << " of " << steps
            << " steps left inverted tetrahedra or a node moved further than the body is "
               "large (at most "
            << most_inverted_ << " inverted, a node moved up to " << largest_move_ << " m, body "
            << body_size_ << " m)\n";
}

}  // namespace fem
