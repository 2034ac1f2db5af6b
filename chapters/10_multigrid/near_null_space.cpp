// Chapter 10: the near-null space (see near_null_space.hpp).
#include "chapters/10_multigrid/near_null_space.hpp"

#include <Eigen/LU>

namespace fem::ch10 {

std::vector<NodeModes> rigid_body_modes(const Eigen::VectorXd& X,
                                        const std::vector<NodeConstraint>& constraints,
                                        const std::vector<int>& aggregate, int count, int modes) {
  const int n = static_cast<int>(aggregate.size());
  std::vector<Eigen::Vector3d> centroid(count, Eigen::Vector3d::Zero());
  std::vector<int> members(count, 0);
  for (int i = 0; i < n; ++i) {
    centroid[aggregate[i]] += X.segment<3>(3 * i);
    ++members[aggregate[i]];
  }
  std::vector<NodeModes> modes_at(n);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d r = X.segment<3>(3 * i) - centroid[aggregate[i]] / members[aggregate[i]];
    auto& N = modes_at[i];
    N.setZero();
    N.leftCols<3>().setIdentity();
    if (modes > 3) {
      N.rightCols<3>() << 0.0, r.z(), -r.y(),  // w x r = -[r]_x w
          -r.z(), 0.0, r.x(),                  //
          r.y(), -r.x(), 0.0;
    }
  }
  for (const auto& c : constraints) modes_at[c.node] = c.filter * modes_at[c.node];
  return modes_at;
}

void improve_modes(const Level<3>& level, int sweeps, std::vector<NodeModes>& modes) {
  const auto& A = level.A;
  const int n = level.nodes();
  for (int s = 0; s < 2 * sweeps; ++s)
    for (int t = 0; t < n; ++t) {
      const int i = s % 2 == 0 ? t : n - 1 - t;
      NodeModes sum = NodeModes::Zero();
      for (int k = A.row_start[i]; k < A.row_start[i + 1]; ++k)
        sum.noalias() += level.values[k] * modes[A.column[k]];
      modes[i] -= level.values[level.diagonal[i]].inverse() * sum;
    }
}

}  // namespace fem::ch10
