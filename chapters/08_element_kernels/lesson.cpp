// Chapter 08's lesson table: `fem_lessons rotations` (per element, the rotation by JacobiSVD and by Newton (cold and warm-started), the element blocks from a stored K0 and in closed form).
#include "chapters/08_element_kernels/lesson.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>

#include "chapters/08_element_kernels/stepper.hpp"
#include "common/lesson.hpp"
#include "common/model.hpp"

namespace fem::ch08 {

namespace {

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
  const std::vector<Eigen::Quaterniond> previous = stepper.elements().rotations();
  const std::vector<Eigen::Quaterniond> before = stepper.elements().previous_rotations();
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
  std::vector<ch08::ElementShape> shapes = stepper.elements().shapes();
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
    scenes << (scenes.tellp() > 0 ? ", " : "") << name << " " << run.elements().total_fallbacks() << " of "
           << static_cast<long long>(steps) * static_cast<long long>(m);
  }

  const auto mib = [m](std::size_t bytes) { return static_cast<double>(bytes * m) / (1 << 20); };
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
      << mesh_name(bench_scene) << " ("
      << bench_scene.mesh.num_tets() << " tets); median of " << repeat
      << " sweeps over all elements. Largest difference from common/'s rotation: "
      << std::scientific << std::setprecision(1) << difference << std::fixed
      << ". SVD fallbacks of the stepper over " << steps << " steps (elements x steps): "
      << scenes.str() << ". " << measured_on() << ". Generated by `fem_lessons rotations`.\n";
  volatile double keep = sink.sum();
  (void)keep;
  return out.str();
}


}  // namespace

std::vector<Lesson> lessons() {
  return {{"rotations", "per element: rotation by SVD and by Newton; blocks from K0 and closed form", "meshes/plate_poster.msh", nullptr,
           [](const LessonRun& run) { return rotations_table(run.scene, run.steps); }}};
}

}  // namespace fem::ch08
