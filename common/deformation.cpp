#include "common/deformation.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <iostream>
#include <limits>
#include <string>

namespace fem {
namespace {

constexpr std::array<std::array<int, 2>, 6> kEdges = {
    {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}}};

bool does_work(const Scene& scene) {
  return !scene.external_forces.empty() ||
         std::any_of(scene.constraints.begin(), scene.constraints.end(),
                     [](const NodeConstraint& c) { return !c.target_velocity.isZero(); });
}

}  // namespace

DeformationProbe::DeformationProbe(const Scene& scene)
    : scene_(scene), model_(scene), energy_balance_(!does_work(scene)) {
  rest_edges_.reserve(6 * scene.mesh.tets.size());
  for (const Eigen::Vector4i& t : scene.mesh.tets)
    for (const auto& [a, b] : kEdges)
      rest_edges_.push_back((scene.mesh.X.col(t[a]) - scene.mesh.X.col(t[b])).norm());
}

DeformationCheck DeformationProbe::check(const State& state) const {
  DeformationCheck check;
  check.elements = static_cast<int>(scene_.mesh.tets.size());
  const Eigen::VectorXd& x = state.x;
  for (std::size_t e = 0; e < scene_.mesh.tets.size(); ++e) {
    const Eigen::Vector4i& t = scene_.mesh.tets[e];
    Eigen::Matrix3d Ds;
    for (int k = 0; k < 3; ++k) Ds.col(k) = x.segment<3>(3 * t[k + 1]) - x.segment<3>(3 * t[0]);
    if (!(Ds.determinant() > 0.0)) ++check.inverted;
    for (std::size_t i = 0; i < kEdges.size(); ++i) {
      const double length =
          (x.segment<3>(3 * t[kEdges[i][0]]) - x.segment<3>(3 * t[kEdges[i][1]])).norm();
      check.largest_stretch = std::max(check.largest_stretch, length / rest_edges_[6 * e + i]);
    }
  }
  if (energy_balance_) {
    const Eigen::VectorXd rest = Eigen::Map<const Eigen::VectorXd>(scene_.mesh.X.data(), x.size());
    const double kinetic = 0.5 * state.v.dot(model_.lumped_mass.cwiseProduct(state.v));
    const double elastic = elastic_energy(model_, scene_, x);
    check.energy_content = kinetic + elastic;
    check.energy = check.energy_content - model_.gravity_force.dot(x - rest);
    // x - rest is known to the coordinates' last digits only: at a tiny step the whole energy
    // is below that, and its sign is noise (a false "unstable" at --dt 1e-12).
    check.energy_noise = 64.0 * std::numeric_limits<double>::epsilon() *
                         model_.gravity_force.cwiseAbs().dot(x.cwiseAbs() + rest.cwiseAbs());
  }
  return check;
}

bool DeformationReport::after_step(int step, const DeformationCheck& check) {
  largest_content_ = std::max(largest_content_, check.energy_content);
  inverted_run_ = check.inverted > 0 ? inverted_run_ + 1 : 0;
  share_run_ = check.inverted > limits_.inverted_share * check.elements ? share_run_ + 1 : 0;
  const bool inverted =
      inverted_run_ >= limits_.inverted_steps || share_run_ >= limits_.inverted_share_steps;
  // The rest state, where every run starts, holds no energy: growth is energy above 0.
  const bool stretched = check.largest_stretch > limits_.stretch;
  const bool energy =
      largest_content_ > 0.0 &&
      check.energy > std::max(limits_.energy_growth * largest_content_, check.energy_noise);
  troubled_steps_ += (inverted || stretched || energy) ? 1 : 0;
  const auto warn_once = [&](bool trouble, bool& warned, const std::string& what) {
    if (!trouble || warned) return false;
    std::cerr << "warning: step " << step << ": " << what << "\n";
    return warned = true;
  };
  const bool a =
      warn_once(inverted, warned_inverted_,
                std::to_string(check.inverted) + " of " + std::to_string(check.elements) +
                    " tetrahedra inverted, some of them for " + std::to_string(inverted_run_) +
                    " steps in a row: the body folds through itself, which the step cannot "
                    "undo; try a smaller --dt (or a stiffer --E for this load)");
  const bool b = warn_once(stretched, warned_stretch_,
                           "an element stretched to " + std::to_string(check.largest_stretch) +
                               " times its rest size: the run has blown up; try a smaller --dt, "
                               "more damping (--beta), or a tighter --tol");
  const bool c = warn_once(energy, warned_energy_,
                           "the body's energy grew to " + std::to_string(check.energy) +
                               " J above its rest, which damping and the implicit step only take "
                               "away: the step is unstable; try a smaller --dt or a tighter --tol");
  return a || b || c;
}

void DeformationReport::summary(int steps) const {
  if (troubled_steps_ == 0) return;
  std::cerr << "warning: " << troubled_steps_ << " of " << steps
            << " steps were in trouble (see the warnings above)\n";
}

}  // namespace fem
