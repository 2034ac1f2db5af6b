// The lesson of chapter 02, measured: each vector statement of chapter 01 beside its
// rewrite in chapter 02, and the heap allocations each one makes. Used by the chapter's
// test (which asserts the counts) and by `fem_lessons noalias` (which prints the table
// in the chapter's README). Needs the allocation counter linked into the binary.
#pragma once

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCore>
#include <functional>
#include <string>
#include <vector>

#include "chapters/01_naive/stepper.hpp"
#include "common/alloc_counter.hpp"
#include "common/model.hpp"

namespace fem::ch02 {

struct StatementCount {
  std::string before_code, after_code;
  long long before = 0, after = 0;  // heap allocations of one execution
};

// The operands of the step's vector statements, with the sizes and patterns of a real
// step of chapter 01 on the given scene.
struct StatementOperands {
  explicit StatementOperands(const Scene& scene)
      : h(scene.dt), alpha(scene.damping.alpha), beta(scene.damping.beta) {
    ch01::NaiveStepper naive(scene, {});
    State state = rest_state(scene);
    naive.step(state);
    const int n = static_cast<int>(state.x.size());
    dfdx = naive.dfdx();
    A = naive.system_matrix();
    mass = Model(scene).lumped_mass;
    M.resize(n, n);
    M.setIdentity();
    M.diagonal() = mass;
    dfdv = -alpha * M + beta * dfdx;  // Rayleigh damping with the scene's alpha and beta
    S.resize(n, n);
    S.setIdentity();
    v = state.v;
    f = Eigen::VectorXd::Ones(n);
    z = Eigen::VectorXd::Zero(n);
    b = tmp = rhs = dv = filtered_b = Eigen::VectorXd::Zero(n);
    sparse_f.resize(n);
    for (const auto& e : scene.external_forces) sparse_f.coeffRef(3 * e.node + 1) = e.force.y();
    if (sparse_f.nonZeros() == 0) sparse_f.coeffRef(0) = 1.0;
    cg.compute(A);
  }
  // The scene's time step and damping: the statements compute what the steppers compute.
  double h, alpha, beta;
  Eigen::SparseMatrix<double> dfdx, M, dfdv, A, S;
  Eigen::SparseVector<double> sparse_f;
  Eigen::VectorXd mass, v, f, z, b, tmp, rhs, dv, filtered_b;
  Eigen::ConjugateGradient<Eigen::SparseMatrix<double>> cg;
  std::vector<Eigen::Triplet<double>> triplets;  // reused: keeps its capacity
};

// Counts the allocations of one run of `statement` (run once before, so that vectors
// that need a first sizing are sized: we count the steady state of a step).
inline long long allocations_of(const std::function<void()>& statement) {
  statement();
  alloc::Scope scope;
  statement();
  return scope.allocations();
}

#define FEM_STATEMENT(...) #__VA_ARGS__, [&] { __VA_ARGS__; }

inline std::vector<StatementCount> count_statements(const Scene& scene) {
  StatementOperands o(scene);
  // Plain names, so that the measured code reads as in the steppers.
  const auto &dfdx = o.dfdx, &dfdv = o.dfdv, &A = o.A, &S = o.S;
  const auto& sparse_f = o.sparse_f;
  const auto &mass = o.mass, &v = o.v, &f = o.f, &z = o.z;
  auto &b = o.b, &tmp = o.tmp, &rhs = o.rhs, &dv = o.dv, &filtered_b = o.filtered_b;
  auto& cg = o.cg;
  auto& triplets = o.triplets;
  const double h = o.h, alpha = o.alpha, beta = o.beta;
  const int n = static_cast<int>(v.size());
  std::vector<StatementCount> out;
  const auto add = [&out](const char* before_code, const std::function<void()>& before,
                          const char* after_code, const std::function<void()>& after) {
    out.push_back({before_code, after_code, allocations_of(before), allocations_of(after)});
  };
  // The poster's own example, with our df/dx, velocity and sparse interaction force.
  add(FEM_STATEMENT(rhs += h * (dfdx * ((h * v) + sparse_f))),
      FEM_STATEMENT(tmp = h * v; tmp += sparse_f; rhs.noalias() += h * (dfdx * tmp)));
  // The right-hand side of the step.
  add(FEM_STATEMENT(b = h * (f + dfdv * v + h * (dfdx * v))),
      FEM_STATEMENT(tmp = (h + beta) * v; b.noalias() = h * (dfdx * tmp);
                    b += h * f - (h * alpha) * mass.cwiseProduct(v)));
  // The filtered right-hand side.
  add(FEM_STATEMENT(filtered_b = S * (b - A * z)),
      FEM_STATEMENT(tmp = b; tmp.noalias() -= A * z; filtered_b.noalias() = S * tmp));
  // The solution plus the prescribed velocity change (CG's own allocations included).
  add(FEM_STATEMENT(dv = cg.solve(filtered_b) + z),
      FEM_STATEMENT(dv = cg.solve(filtered_b); dv += z));
  // The triplet list of S: a local vector grows by doubling every step.
  add(FEM_STATEMENT(std::vector<Eigen::Triplet<double>> s;
                    for (int k = 0; k < n; ++k) s.emplace_back(k, k, 1.0)),
      FEM_STATEMENT(triplets.clear();
                    for (int k = 0; k < n; ++k) triplets.emplace_back(k, k, 1.0)));
  return out;
}

#undef FEM_STATEMENT

}  // namespace fem::ch02
