// Chapter 08's lesson table: `fem_lessons rotations` (per element, the rotation by JacobiSVD and by
// Newton (cold and warm-started), the element blocks from a stored K0 and in closed form).
#include "chapters/08_element_kernels/lesson.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <iomanip>
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

// What the rows measure: the deformation gradients of step 21 of a real run, and the warm
// starts the stepper has for it (the rotations of the two steps before).
struct ElementSample {
  Model model;
  std::vector<Eigen::Matrix3d> F;
  std::vector<Eigen::Quaterniond> previous, before;
  std::vector<ElementShape> shapes;
  std::size_t size() const { return F.size(); }
};

ElementSample sample_step(const Scene& scene) {
  ElementKernelsStepper stepper(scene, {});
  State state = rest_state(scene);
  for (int k = 0; k < 20; ++k) stepper.step(state);
  ElementSample sample{Model(scene),
                       {},
                       stepper.elements().fused().rotations(),
                       stepper.elements().fused().previous_rotations(),
                       stepper.elements().fused().shapes()};
  for (std::size_t e = 0; e < sample.model.tets.size(); ++e)
    sample.F.push_back(
        deformation_gradient(sample.model.rest[e], gather(state.x, sample.model.tets[e])));
  return sample;
}

// Newton's iterations summed over the elements, and the elements where it cannot decide.
struct NewtonCount {
  long long iterations = 0, undecided = 0;
  void add(int k) { k > 0 ? iterations += k : ++undecided; }
  std::string mean(std::size_t elements) const {
    std::ostringstream s;
    s << std::fixed << std::setprecision(2)
      << static_cast<double>(iterations) / static_cast<double>(elements - undecided);
    if (undecided > 0) s << " (" << undecided << " undecided)";
    return s.str();
  }
};

std::string table_row(const std::string& what, double ns, double reference_ns,
                      const std::string& last) {
  std::ostringstream row;
  row << std::fixed << "| " << what << " | " << std::setprecision(1) << ns << " | "
      << std::setprecision(2) << reference_ns / ns << "x | " << last << " |\n";
  return row.str();
}

// Newton from a start (q = start(e)), counted, as ns per element.
template <class Start>
double newton_ns(const ElementSample& sample, int repeat, Start&& start, NewtonCount& count) {
  std::vector<Eigen::Quaterniond> q(sample.size());
  return 1e6 / static_cast<double>(sample.size()) * time_ms(repeat, [&] {
           count = NewtonCount{};
           for (std::size_t e = 0; e < sample.size(); ++e) {
             q[e] = start(e);
             count.add(newton_polar_rotation(sample.F[e], q[e]));
           }
         });
}

// The rotation rows; R gets the stepper's rotations, difference their largest from common/'s.
std::string rotation_rows(const ElementSample& s, int repeat, std::vector<Eigen::Matrix3d>& R,
                          double& difference) {
  const std::size_t m = s.size();
  const double to_ns = 1e6 / static_cast<double>(m);  // median ms of a sweep -> ns/element
  R.resize(m);
  const double svd = to_ns * time_ms(repeat, [&] {
                       for (std::size_t e = 0; e < m; ++e) R[e] = polar_rotation(s.F[e]);
                     });
  const double eigensolver = to_ns * time_ms(repeat, [&] {
                               for (std::size_t e = 0; e < m; ++e)
                                 R[e] = polar_by_eigensolver(s.F[e]);
                             });
  NewtonCount cold, warm, predicted;
  const auto identity = [](std::size_t) { return Eigen::Quaterniond::Identity(); };
  const auto last = [&](std::size_t e) { return s.previous[e]; };
  const auto extrapolated = [&](std::size_t e) {
    return predicted_rotation(s.previous[e], s.before[e]);
  };
  const double cold_ns = newton_ns(s, repeat, identity, cold);
  const double warm_ns = newton_ns(s, repeat, last, warm);
  const double predicted_ns = newton_ns(s, repeat, extrapolated, predicted);
  long long fallbacks = 0;
  const double fast = to_ns * time_ms(repeat, [&] {
                        for (std::size_t e = 0; e < m; ++e) {
                          Eigen::Quaterniond q = extrapolated(e);
                          R[e] = fast_polar_rotation(s.F[e], q, fallbacks);
                        }
                      });
  difference = 0.0;  // the answers, against common/'s
  for (std::size_t e = 0; e < m; ++e)
    difference = std::max(difference, (R[e] - polar_rotation(s.F[e])).cwiseAbs().maxCoeff());
  return "| rotation of one element | ns per element | vs JacobiSVD | iterations |\n"
         "| --- | ---: | ---: | ---: |\n" +
         table_row("`JacobiSVD<Matrix3d>`, U V^T (common/, chapters 01-07)", svd, svd, "-") +
         table_row(
             "`SelfAdjointEigenSolver::computeDirect` of F^T F (no inversion, squared "
             "condition)",
             eigensolver, svd, "-") +
         table_row("Newton, cold (from the identity)", cold_ns, svd, cold.mean(m)) +
         table_row("Newton, warm (from the previous step's rotation)", warm_ns, svd, warm.mean(m)) +
         table_row("Newton, warm (predicted from the last two steps' rotations)", predicted_ns, svd,
                   predicted.mean(m)) +
         table_row("predicted start, Newton, SVD fallback: the stepper's (chapter 08)", fast, svd,
                   "-");
}

// The element blocks: sixteen -R K0_ab R^T from the stored K0 (chapter 07), against the ten
// distinct blocks in closed form from the shape gradients (chapter 08).
std::string block_rows(const ElementSample& s, const std::vector<Eigen::Matrix3d>& R, int repeat) {
  const std::size_t m = s.size();
  const double to_ns = 1e6 / static_cast<double>(m);
  Eigen::Matrix3d sink = Eigen::Matrix3d::Zero();  // keeps the blocks from being optimized out
  const double stored = to_ns * time_ms(repeat, [&] {
                          for (std::size_t e = 0; e < m; ++e)
                            for (int ab = 0; ab < 16; ++ab)
                              sink += dfdx_block(s.model.rest[e], R[e], ab / 4, ab % 4);
                        });
  std::array<Eigen::Matrix3d, 10> K;
  const double closed = to_ns * time_ms(repeat, [&] {
                          for (std::size_t e = 0; e < m; ++e) {
                            stiffness_blocks(rotated_gradients(R[e], s.shapes[e].Dm_inv),
                                             s.shapes[e].mu_volume, s.shapes[e].lambda_volume, K);
                            for (const Eigen::Matrix3d& k : K) sink += k;
                          }
                        });
  volatile double keep = sink.sum();
  (void)keep;
  const auto rest_data = [m](std::size_t bytes) {
    std::ostringstream cell;
    cell << std::fixed << bytes << " | " << std::setprecision(2)
         << static_cast<double>(bytes * m) / (1 << 20);
    return cell.str();
  };
  return "| element blocks of -df/dx | ns per element | vs stored K0 | rest data per element "
         "(bytes) | rest data per step (MiB) |\n| --- | ---: | ---: | ---: | ---: |\n" +
         table_row("sixteen `-R K0_ab R^T` from the stored K0 (chapter 07)", stored, stored,
                   rest_data(sizeof(ElementRest))) +
         table_row("ten closed-form blocks from the shape gradients (chapter 08)", closed, stored,
                   rest_data(sizeof(ElementShape)));
}

// How often the stepper falls back to the SVD on the benchmark's scenes.
std::string fallback_counts(const Scene& bench_scene, int steps) {
  std::ostringstream scenes;
  for (const std::string& name : scene_names()) {
    progress(std::to_string(steps) + " steps of the " + name + " scene, counting SVD fallbacks");
    Scene scene = make_scene(name, bench_scene.mesh, bench_scene.material);
    scene.dt = bench_scene.dt;
    ElementKernelsStepper run(scene, {});
    State s = rest_state(scene);
    for (int k = 0; k < steps; ++k) run.step(s);
    scenes << (scenes.tellp() > 0 ? ", " : "") << name << " "
           << run.elements().fused().total_fallbacks() << " of "
           << static_cast<long long>(steps) * bench_scene.mesh.num_tets();
  }
  return scenes.str();
}

std::string rotations_table(const Scene& bench_scene, int steps) {
  const ElementSample sample = sample_step(bench_scene);
  const int repeat = std::max(5, steps);
  std::vector<Eigen::Matrix3d> R;
  double difference = 0.0;
  std::ostringstream out;
  out << rotation_rows(sample, repeat, R, difference) << "\n"
      << block_rows(sample, R, repeat) << "\n"
      << "Step 21 of the " << bench_scene.name << " scene on " << mesh_name(bench_scene) << " ("
      << bench_scene.mesh.num_tets() << " tets); median of " << repeat
      << " sweeps over all elements. Largest difference from common/'s rotation: "
      << std::scientific << std::setprecision(1) << difference << std::fixed
      << ". SVD fallbacks of the stepper over " << steps
      << " steps (elements x steps): " << fallback_counts(bench_scene, steps) << ". "
      << measured_on() << ". Generated by `fem_lessons rotations`.\n";
  return out.str();
}

}  // namespace

std::vector<Lesson> lessons() {
  return {{"rotations",
           "per element: rotation by SVD and by Newton; blocks from K0 and closed form",
           "meshes/plate_poster.msh", nullptr,
           [](const LessonRun& run) { return rotations_table(run.scene, run.steps); }}};
}

}  // namespace fem::ch08
