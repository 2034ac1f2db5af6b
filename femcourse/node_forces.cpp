#include "femcourse/node_forces.hpp"

#include <algorithm>

#include "chapters/08_element_kernels/element_kernels.hpp"

namespace femcourse::detail {

NodeForces::NodeForces(const fem::Model& model, const fem::Scene& scene)
    : model_(model),
      forces_(model.tets.size()),
      element_stamps_(model.tets.size()),
      node_stamps_(static_cast<std::size_t>(model.num_nodes)),
      first_(static_cast<std::size_t>(model.num_nodes) + 1, 0),
      f_(model.gravity_force) {
  const std::size_t elements = model.tets.size();
  const fem::Lame lame =
      fem::lame_from_young_poisson(scene.material.youngs_modulus, scene.material.poisson_ratio);
  for (auto& d : dm_) d.resize(elements);
  mu_volume_.resize(elements);
  lambda_volume_.resize(elements);
  for (std::size_t e = 0; e < elements; ++e) {
    const fem::ch08::ElementShape shape = fem::ch08::make_element_shape(model.rest[e], lame);
    for (int k = 0; k < 9; ++k) dm_[static_cast<std::size_t>(k)][e] = shape.Dm_inv(k / 3, k % 3);
    mu_volume_[e] = shape.mu_volume;
    lambda_volume_[e] = shape.lambda_volume;
  }
  for (auto& c : floor_starts_) c.resize(elements);
  for (auto& c : starts_) c.resize(elements);
  restart();
  for (const Eigen::Vector4i& t : model.tets)
    for (int a = 0; a < 4; ++a) ++first_[static_cast<std::size_t>(t[a]) + 1];
  for (std::size_t n = 0; n + 1 < first_.size(); ++n) first_[n + 1] += first_[n];
  corners_.resize(static_cast<std::size_t>(first_.back()));
  std::vector<int> next(first_.begin(), first_.end() - 1);
  for (std::size_t e = 0; e < elements; ++e)
    for (int a = 0; a < 4; ++a)
      corners_[static_cast<std::size_t>(next[static_cast<std::size_t>(model.tets[e][a])]++)] =
          4 * static_cast<int>(e) + a;
  staged_.reserve(elements);
}

void NodeForces::restart() {
  for (int c = 0; c < 4; ++c) {
    const double identity = c == 0 ? 1.0 : 0.0;  // (w, x, y, z) of the rest shape's rotation
    std::fill(floor_starts_[c].begin(), floor_starts_[c].end(), identity);
    std::fill(starts_[c].begin(), starts_[c].end(), identity);
  }
  new_positions();
}

void NodeForces::stage_node(int node, Reader reader) {
  const auto n = static_cast<std::size_t>(node);
  if (node_stamps_[n].serves(version_, reader)) return;
  for (int k = first_[n]; k < first_[n + 1]; ++k) {
    const int e = corners_[static_cast<std::size_t>(k)] / 4;
    Stamp& stamp = element_stamps_[static_cast<std::size_t>(e)];
    if (stamp.serves(version_, reader)) continue;
    stamp = {version_, reader};  // staged: computed by compute_staged before anyone reads it
    staged_.push_back(e);
  }
}

void NodeForces::compute_staged(const Eigen::VectorXd& x, Reader reader) {
  // Along the arrays, so that each batch's numbers lie close; all() stages in order already.
  if (!std::is_sorted(staged_.begin(), staged_.end())) std::sort(staged_.begin(), staged_.end());
  const int count = static_cast<int>(staged_.size());
  for (int first = 0; first < count; first += kLanes)
    compute_batch(staged_.data() + first, std::min(kLanes, count - first), x, reader);
  staged_.clear();
}

// Chapter 08's force without its velocity term, lane by lane as chapter 12 lays a batch out:
// -P r_a on corner a, r_a = R g_a, P the linear stress of G = F R^T (ch08::FusedElements::terms),
// equal to common/'s -R K0 (R^T x_e - X_e). Lanes past `count` repeat the last element.
void NodeForces::compute_batch(const int* elements, int count, const Eigen::VectorXd& x,
                               Reader reader) {
  std::array<std::vector<double>, 4>& starts = reader == Reader::floor ? floor_starts_ : starts_;
  Lanes ds[9], dm[9], start[4], q[4], mu, lambda;
  const auto element = [&](int l) {
    return static_cast<std::size_t>(elements[std::min(l, count - 1)]);
  };
  if (count == kLanes && elements[kLanes - 1] == elements[0] + kLanes - 1) {
    // Eight consecutive elements (elastic_forces, a floor under a slab): vector loads.
    const std::size_t e0 = element(0);
    const auto load = [e0](const std::vector<double>& from, Lanes& to) {
#pragma omp simd
      for (int l = 0; l < kLanes; ++l) to.v[l] = from[e0 + static_cast<std::size_t>(l)];
    };
    for (std::size_t k = 0; k < 9; ++k) load(dm_[k], dm[k]);
    for (std::size_t c = 0; c < 4; ++c) load(starts[c], start[c]);
    load(mu_volume_, mu);
    load(lambda_volume_, lambda);
  } else {
    for (int l = 0; l < kLanes; ++l) {
      const std::size_t e = element(l);
      for (std::size_t k = 0; k < 9; ++k) dm[k].v[l] = dm_[k][e];
      for (std::size_t c = 0; c < 4; ++c) start[c].v[l] = starts[c][e];
      mu.v[l] = mu_volume_[e];
      lambda.v[l] = lambda_volume_[e];
    }
  }
  for (int l = 0; l < kLanes; ++l) {
    const Eigen::Vector4i& t = model_.tets[element(l)];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) ds[3 * i + j].v[l] = x[3 * t[j + 1] + i] - x[3 * t[0] + i];
  }
  // `last` and `before` both the start: chapter 08's prediction R_k R_{k-1}^T R_k is then R_k.
  fem::ch12::polar_rotations(ds, dm, start, start, count, q, fallbacks_);

  Lanes R[9], r[3][4], G[3][3];
#pragma omp simd
  for (int l = 0; l < kLanes; ++l) {  // Eigen's Quaternion::toRotationMatrix, written out
    const double w = q[0].v[l], qx = q[1].v[l], qy = q[2].v[l], qz = q[3].v[l];
    R[0].v[l] = 1 - 2 * (qy * qy + qz * qz);
    R[1].v[l] = 2 * (qx * qy - w * qz);
    R[2].v[l] = 2 * (qx * qz + w * qy);
    R[3].v[l] = 2 * (qx * qy + w * qz);
    R[4].v[l] = 1 - 2 * (qx * qx + qz * qz);
    R[5].v[l] = 2 * (qy * qz - w * qx);
    R[6].v[l] = 2 * (qx * qz - w * qy);
    R[7].v[l] = 2 * (qy * qz + w * qx);
    R[8].v[l] = 1 - 2 * (qx * qx + qy * qy);
  }
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
#pragma omp simd
      for (int l = 0; l < kLanes; ++l)
        r[i][j + 1].v[l] = R[3 * i].v[l] * dm[3 * j].v[l] + R[3 * i + 1].v[l] * dm[3 * j + 1].v[l] +
                           R[3 * i + 2].v[l] * dm[3 * j + 2].v[l];
    }
#pragma omp simd
    for (int l = 0; l < kLanes; ++l) r[i][0].v[l] = -(r[i][1].v[l] + r[i][2].v[l] + r[i][3].v[l]);
  }
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
#pragma omp simd
      for (int l = 0; l < kLanes; ++l)
        G[i][j].v[l] = ds[3 * i].v[l] * r[j][1].v[l] + ds[3 * i + 1].v[l] * r[j][2].v[l] +
                       ds[3 * i + 2].v[l] * r[j][3].v[l];
    }
  Lanes P[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
#pragma omp simd
      for (int l = 0; l < kLanes; ++l) {
        const double diagonal =
            lambda.v[l] * (G[0][0].v[l] + G[1][1].v[l] + G[2][2].v[l] - 3.0) - 2.0 * mu.v[l];
        P[i][j].v[l] = mu.v[l] * (G[i][j].v[l] + G[j][i].v[l]) + (i == j ? diagonal : 0.0);
      }
    }
  for (int l = 0; l < count; ++l) {
    const auto e = static_cast<std::size_t>(elements[l]);
    for (int i = 0; i < 3; ++i)
      for (int a = 0; a < 4; ++a)
        forces_[e](i, a) = -(P[i][0].v[l] * r[0][a].v[l] + P[i][1].v[l] * r[1][a].v[l] +
                             P[i][2].v[l] * r[2][a].v[l]);
    for (std::size_t c = 0; c < 4; ++c) {
      if (reader == Reader::floor) floor_starts_[c][e] = q[c].v[l];
      starts_[c][e] = q[c].v[l];
    }
  }
}

Eigen::Vector3d NodeForces::at(int node, const Eigen::VectorXd& x, Reader reader) {
  const auto n = static_cast<std::size_t>(node);
  if (!node_stamps_[n].serves(version_, reader)) {
    stage_node(node, reader);
    compute_staged(x, reader);
    sum_node(n, reader);
  }
  return f_.segment<3>(3 * node);
}

// In element order, as common/'s pass sums them. The node's elements must be computed.
void NodeForces::sum_node(std::size_t n, Reader reader) {
  Eigen::Vector3d f = model_.gravity_force.segment<3>(3 * static_cast<Eigen::Index>(n));
  for (int k = first_[n]; k < first_[n + 1]; ++k) {
    const int corner = corners_[static_cast<std::size_t>(k)];
    f += forces_[static_cast<std::size_t>(corner / 4)].col(corner % 4);
  }
  f_.segment<3>(3 * static_cast<Eigen::Index>(n)) = f;
  node_stamps_[n] = {version_, reader};
}

const Eigen::VectorXd& NodeForces::all(const Eigen::VectorXd& x) {
  for (std::size_t e = 0; e < element_stamps_.size(); ++e) {
    if (element_stamps_[e].serves(version_, Reader::app)) continue;
    element_stamps_[e] = {version_, Reader::app};
    staged_.push_back(static_cast<int>(e));
  }
  compute_staged(x, Reader::app);
  // Every node's sum at once, in element order as sum_node adds (so to the same bits): a
  // stream over the elements' forces instead of a gather of each node's.
  f_ = model_.gravity_force;
  double* const f = f_.data();
  for (std::size_t e = 0; e < forces_.size(); ++e) {
    const Eigen::Vector4i& t = model_.tets[e];
    const double* const force = forces_[e].data();  // column-major: corner a at 3 a
    for (int a = 0; a < 4; ++a)
      for (int i = 0; i < 3; ++i) f[3 * t[a] + i] += force[3 * a + i];
  }
  for (Stamp& stamp : node_stamps_)
    if (!stamp.serves(version_, Reader::app)) stamp = {version_, Reader::app};
  return f_;
}

}  // namespace femcourse::detail
