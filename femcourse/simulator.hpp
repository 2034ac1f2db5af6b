// The course's simulator as a library: one elastic body of linear tetrahedra, stepped by
// linearized backward Euler with the stepper of one chapter (by default the last one).
// docs/library.md says how to build against it, what is stable and how to plug in a stepper.
//
// Guarantees (tests/library/test_simulator.cpp asserts each):
//  - step() and set_forces() make no heap allocation once set_forces() has held as many
//    forces as it is given (step() never does).
//  - The positions are those of the chapter's own stepper on the same scene, bit for bit, and
//    bit-identical for any OpenMP thread count (OMP_NUM_THREADS, omp_set_num_threads).
//  - Thread safety: a Body is used by one thread at a time. Its steps run on OpenMP threads
//    inside; two bodies stepped at the same time from two threads are not supported (the
//    single-threaded chapters set Eigen's process-wide thread count during their step).
// Only standard types cross this header, so a program compiled with other flags than the
// library (another -march) links safely against it.
#pragma once

#include <array>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace fem {  // the course's own types, for the advanced section at the end
class Stepper;
struct Scene;
struct State;
struct SolverSettings;
}  // namespace fem

namespace femcourse {

// Per-node velocity constraints: the poster's filters S_i.
struct Constraint {
  enum class Kind {
    Fixed,  // does not move (or moves with `velocity`)
    Plane,  // moves in the plane with normal `direction` (a frictionless floor)
    Line    // moves along `direction`
  };
  int node = 0;
  Kind kind = Kind::Fixed;
  std::array<double, 3> direction{0.0, 0.0, 1.0};  // Plane: the normal; Line: the direction
  std::array<double, 3> velocity{0.0, 0.0, 0.0};   // Fixed only: the prescribed velocity [m/s]
};

struct NodeForce {
  int node = 0;
  std::array<double, 3> force{0.0, 0.0, 0.0};  // [N]
};

// Everything that defines a body. Node i is rest_positions[3i..3i+2]; tetrahedron e is
// tetrahedra[4e..4e+3], positively oriented (det[x1-x0, x2-x0, x3-x0] > 0), and every node
// belongs to at least one tetrahedron.
struct BodyDescription {
  std::vector<double> rest_positions;              // [m], 3 per node
  std::vector<int> tetrahedra;                     // 4 node indices per element, from 0
  double youngs_modulus = 1e5;                     // E [Pa]
  double poisson_ratio = 0.3;                      // nu, in (-1, 0.5)
  double density = 1000.0;                         // rho [kg/m^3]
  double damping_alpha = 0.1;                      // Rayleigh damping: mass part [1/s]
  double damping_beta = 0.005;                     //                   stiffness part [s]
  std::vector<Constraint> constraints;             // at most one per node
  std::array<double, 3> gravity{0.0, 0.0, -9.81};  // [m/s^2]
  double time_step = 0.01;                         // [s]
  double solver_tolerance = 1e-4;                  // CG stops at ||r|| <= tolerance ||b||
  int solver_max_iterations = 2000;
  std::string chapter;  // "12_half_the_bytes", "12", "half_the_bytes"; empty: the last chapter
};

// What the last step cost, by the poster's phases [s], and how its linear solve went.
struct StepProfile {
  double forces = 0.0, dfdx = 0.0, compose = 0.0, constraints = 0.0, solve = 0.0, step = 0.0;
  long long allocations = 0;  // heap allocations in the step (0 unless the counter is linked)
  int iterations = 0;         // CG iterations
  double relative_residual = 0.0;
  bool converged = true;
};

// Thrown by Body::step for a step that cannot be trusted: non-finite positions or velocities,
// or a linear solve that overflowed or stopped at its cap worse than no solve at all.
struct StepDiverged : std::runtime_error {
  StepDiverged(long long step, const std::string& reason);
  long long step;      // counted from 1
  std::string reason;  // e.g. "non-finite positions or velocities"
};

class Body {
 public:
  // Throws std::invalid_argument naming the first bad element or node: an index out of range,
  // a zero-volume or inverted tetrahedron, a NaN, a node in no tetrahedron, a constraint on a
  // missing node, a bad material or time step, an unknown chapter.
  explicit Body(const BodyDescription& description);
  ~Body();
  Body(Body&&) noexcept;
  Body& operator=(Body&&) noexcept;

  // One step of time_step. Throws StepDiverged if the step cannot be trusted; the state is then
  // that of the failed step.
  void step();
  // Replaces the external forces (the mouse drag) from the next step on; {} removes them.
  // Throws std::invalid_argument for a missing node or a non-finite force.
  void set_forces(const std::vector<NodeForce>& forces);

  int num_nodes() const;
  int num_tetrahedra() const;
  const double* positions() const;   // 3 * num_nodes() values [m], node-major
  const double* velocities() const;  // 3 * num_nodes() values [m/s]
  std::array<double, 3> position(int node) const;
  double time() const;                 // [s] since rest
  const StepProfile& profile() const;  // of the last step
  const std::string& chapter() const;  // the chapter's id, e.g. "12_half_the_bytes"
  // Steps on with another chapter's stepper from the current state (the viewer's chapter
  // switch); throws std::invalid_argument for an unknown chapter and changes nothing then.
  void set_chapter(const std::string& chapter);

  // ---- advanced: the course's own types (include "common/stepper.hpp") -----------------
  // A stepper of one's own: any fem::Stepper built from the body's scene (docs/library.md).
  using StepperFactory =
      std::function<std::unique_ptr<fem::Stepper>(const fem::Scene&, const fem::SolverSettings&)>;
  Body(const BodyDescription& description, const StepperFactory& make_stepper);
  // A body on a scene made by the course's code (fem_sim, the viewer); the scene's own
  // constraints and forces are kept.
  Body(fem::Scene scene, const fem::SolverSettings& solver, const std::string& chapter);
  const fem::Scene& scene() const;
  const fem::State& state() const;
  // Continues from another body's state of the same mesh (the viewer after a change of
  // material); throws std::invalid_argument for another number of nodes.
  void set_state(const fem::State& state);
  const fem::Stepper& stepper() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The body of a gmsh .msh file's tetrahedra; description's arrays are ignored, its other
// fields used. Needs the femcourse::mesh_gmsh target (gmsh); throws fem::MeshError otherwise.
Body body_from_gmsh_file(const std::string& path, const BodyDescription& description);

}  // namespace femcourse
