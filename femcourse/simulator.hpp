// The course's simulator as a library: one elastic body of linear tetrahedra, stepped by
// linearized backward Euler with the stepper of one chapter (by default the last one).
// docs/library.md says how to build against it, what is stable and how to plug in a stepper.
//
// Guarantees (tests/library/test_simulator.cpp asserts each):
//  - step() and set_forces() make no heap allocation once set_forces() has held as many
//    forces as it is given (step() never does while the constraints stay as they are).
//  - The positions are those of the chapter's own stepper on the same scene, bit for bit, and
//    bit-identical for any thread count.
//  - A call that throws (other than step()) leaves the body exactly as it was.
//  - Thread safety: a Body is used by one thread at a time; two bodies may be stepped from two
//    threads at once (each step sets its own thread count on the thread that steps it).
//  - Nothing is printed: warnings go to the body's handler, or wait in its queue.
// Only standard types cross this header (apart from the advanced section at the end), so a
// program compiled with other flags than the library (another -march, no OpenMP) links safely
// against it. A standard library of another ABI (libc++, _GLIBCXX_DEBUG, the pre-C++11 string)
// would lay out BodyDescription differently: such a program does not link (FEMCOURSE_ABI).
#pragma once

#include <array>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

// The standard library's mode is part of every name below, so that a program built in
// another mode fails to link, naming it ("undefined reference to femcourse::glibcxx_debug::
// Body::Body"), instead of reading a BodyDescription of another layout.
#if defined(_LIBCPP_VERSION)
#define FEMCOURSE_ABI libcxx
#elif defined(_GLIBCXX_DEBUG)
#define FEMCOURSE_ABI glibcxx_debug
#elif defined(_GLIBCXX_USE_CXX11_ABI) && _GLIBCXX_USE_CXX11_ABI == 0
#define FEMCOURSE_ABI glibcxx_old_string
#else
#define FEMCOURSE_ABI libstdcxx
#endif

namespace fem {  // the course's own types, for the advanced section at the end
class Stepper;
struct Scene;
struct State;
struct SolverSettings;
}  // namespace fem

namespace femcourse {
inline namespace FEMCOURSE_ABI {

// Per-node velocity constraints, given at construction (grab() and set_floor() add their own
// while the body runs). Every kind is two-sided: a node on a Plane stays on it however it is
// pulled (set_floor() is the one-sided floor).
struct Constraint {
  enum class Kind {
    Fixed,  // does not move (or moves with `velocity`)
    Plane,  // moves in the plane through its position with normal `direction`
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
  // Each step() takes this many steps of time_step / substeps. The floor puts a penetrating
  // node on its plane after a step, so a fast impact (a block dropped 2 m at 60 Hz) squashes
  // and inverts elements for a few frames at 1; the body warns then, naming this setting.
  int substeps = 1;
  double solver_tolerance = 1e-4;  // CG stops at ||r|| <= tolerance ||b||, in (0, 1)
  int solver_max_iterations = 2000;
  std::string chapter;  // "12_half_the_bytes", "12", "half_the_bytes"; empty: the last chapter
  // Threads that step this body (chapters 09 on; the earlier ones use one): every step runs
  // on exactly this many. 0 (not asked): one thread below kSmallBodyNodes nodes, where a
  // second thread shortens the median step but another process on the machine turns each of
  // its waits into a hitch (docs/library.md, frame times); above, OpenMP's count, or one
  // thread while that is faster (chapter 09's adaptive team). threads_used() says what ran.
  int threads = 0;
};
constexpr int kSmallBodyNodes = 20000;

// What the last step cost, by the poster's phases [s], and how its linear solve went.
struct StepProfile {
  double forces = 0.0, dfdx = 0.0, compose = 0.0, constraints = 0.0, solve = 0.0, step = 0.0;
  long long allocations = 0;  // heap allocations in the step (0 unless the counter is linked)
  int iterations = 0;         // CG iterations
  double relative_residual = 0.0;
  bool converged = true;
};

// Thrown by Body::step for a step that cannot be trusted: non-finite positions or velocities,
// or a linear solve that overflowed or stopped at its cap worse than no solve at all. what()
// says what to change, in BodyDescription's terms.
struct StepDiverged : std::runtime_error {
  StepDiverged(long long step, const std::string& reason, const std::string& advice);
  long long step;      // counted from 1
  std::string reason;  // e.g. "non-finite positions or velocities"
};

// A saved state: what restore_state() needs to go on exactly as the body went on.
struct BodyState {
  std::vector<double> positions, velocities;  // 3 per node
  long long steps = 0;
  std::vector<int> floor_contacts;  // nodes held on the floor (set_floor)
  // The floor the contacts are held on (set_floor's point and normal); restore_state puts it
  // back, or removes the body's floor when the state has none.
  bool floor = false;
  std::array<double, 3> floor_point{0.0, 0.0, 0.0}, floor_normal{0.0, 0.0, 1.0};
  double floor_friction = 0.0;   // set_floor's Coulomb coefficient
  std::vector<int> floor_stuck;  // the contacts that stick (friction), among floor_contacts
};

// The deformation watch (fem_sim's): an element stretched to several times its rest size, or
// a share of the body turned inside out, means the run has blown up even with finite numbers
// (a 1e30 N force, a far too large time step).
struct DeformationStatus {
  int inverted_elements = 0;     // det F <= 0
  double largest_stretch = 1.0;  // max over edges of deformed / rest length
  bool plausible = true;         // stretch under 5 and under 1% of the elements inverted
};

class Body {
 public:
  // Throws std::invalid_argument naming the first bad element or node: an index out of range,
  // a zero-volume or inverted tetrahedron, a NaN, a node in no tetrahedron, a constraint on a
  // missing node, a bad material or time step, an unknown chapter, a bad thread count, or an
  // OMP_NUM_THREADS that is not a count (LLVM's OpenMP runtime would abort the first step).
  explicit Body(const BodyDescription& description);
  ~Body();
  // A moved-from body throws std::logic_error from every call until one is assigned to it.
  Body(Body&&) noexcept;
  Body& operator=(Body&&) noexcept;

  // One step of time_step (in `substeps` sub-steps). Throws StepDiverged if a sub-step cannot be
  // trusted; the state is then what the failed sub-step left: its non-finite positions or
  // velocities, or, where the solve overflowed, finite positions the solve did not change (CG
  // stops at once: common/stepper.hpp, divergence); restore_state() goes back to a saved one.
  // profile() is the last sub-step's.
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
  int threads() const;
  void set_threads(int threads);  // as BodyDescription::threads
  // The threads the last step ran on, as its team recorded them (not the count asked for):
  // 1 for a single-threaded chapter; 0 before the first step.
  int threads_used() const;

  // ---- interaction while it runs ---------------------------------------------------------
  // Each call below changes the body's constraints from the next step on. A chapter's stepper
  // that can change its constraints does so in place; the others are rebuilt from the scene
  // with the new constraints (the slow path: a construction's cost, about 3 ms at 320 nodes;
  // the state, time and forces carry over). changes_constraints_in_place() says which.
  //
  // Holds `nodes` (replacing their own constraints until release()) and moves them all with
  // `velocity` [m/s]. Throws std::invalid_argument for a missing node.
  void grab(const std::vector<int>& nodes, const std::array<double, 3>& velocity = {});
  void move_grabbed(const std::array<double, 3>& velocity);
  void release();  // the grabbed nodes get their own constraints back
  const std::vector<int>& grabbed() const;
  // A one-sided floor: the plane through `point` with normal `normal` (pointing to where the
  // body may go). A free node that ends a step below it is put on it, its velocity into it
  // removed, and held on it until the floor would have to pull it back (its reaction points
  // into the floor): then it is released. Nodes with constraints of their own or grabbed are
  // left alone. Called again (a moving or tilting platform), it lets the contacts go and the
  // next step finds them against the new plane. Throws std::invalid_argument for a zero or
  // non-finite normal, or a negative or non-finite friction.
  //
  // Coulomb friction with coefficient `friction` (0: frictionless, a released body glides on),
  // after each step, by the reactions (reactions()): a sliding contact sticks, its velocity
  // along the floor taken away, where the reaction that leaves it stays inside the cone
  // |R_t| <= friction * R_n, else loses along the floor what the cone allows in one step; a
  // stuck contact is held still and slides again once |R_t| > friction * R_n. One coefficient,
  // kinetic and static.
  void set_floor(const std::array<double, 3>& point, const std::array<double, 3>& normal,
                 double friction = 0.0);
  void remove_floor();
  const std::vector<int>& floor_contacts() const;
  bool changes_constraints_in_place() const;

  // ---- output -----------------------------------------------------------------------------
  // The boundary triangles (faces of exactly one tetrahedron), outward by the right-hand
  // rule, as node indices into positions(): what to draw.
  const std::vector<std::array<int, 3>>& surface() const;
  // The forces that the constraints (own, grabbed, floor) exerted on their nodes in the last
  // step [N]: m dv/dt minus the elastic, gravity, external and mass-damping forces at the new
  // state (the stiffness damping left out). Summed over a support at rest, minus the loads.
  // The read-outs below are callable in any order, and reading them never changes a later
  // step. Each element's forces are computed once per state and shared: reactions() costs the
  // elements of the constrained nodes (those of the floor's contacts the floor computed
  // already), elastic_forces() the others (docs/library.md, frame times, has their price).
  // Their storage is the body's, reused: no allocation once it has held as many values; valid
  // until the body changes.
  const std::vector<NodeForce>& reactions() const;
  // The elastic forces on every node at the current positions [N], 3 * num_nodes() values.
  const std::vector<double>& elastic_forces() const;
  DeformationStatus check_deformation() const;

  // ---- diagnostics ------------------------------------------------------------------------
  // Warnings (a solve stopped at its cap) go to the handler, called on the thread that steps;
  // without one they wait in a queue (the last 64) that take_warnings() empties.
  void set_warning_handler(std::function<void(const std::string&)> handler);
  std::vector<std::string> take_warnings();
  // A state to go back to. Saving restarts the stepper (its warm starts, its refreshed
  // preconditioner), so that from then on the saved state alone decides every step: a body
  // restored to it steps bit-identically to the body that saved it. Costs a construction.
  BodyState save_state();
  // Throws std::invalid_argument, changing nothing, for another number of nodes, a NaN or
  // infinite value, floor contacts without a floor, or a contact on a missing node, on a node
  // named twice or on a node with a constraint of its own or grabbed.
  void restore_state(const BodyState& state);

  // ---- advanced: the course's own types (include "common/stepper.hpp") -----------------
  // Inside the source tree only (add_subdirectory): the installed package has no course
  // headers. A stepper of one's own: any fem::Stepper built from the body's scene.
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
  Impl& impl();
  const Impl& impl() const;
  std::unique_ptr<Impl> impl_;
};

// The body of a gmsh .msh file's tetrahedra; description's arrays are ignored, its other
// fields used. ASCII MSH 4.1 or 2.2, read by the course's own reader (no gmsh SDK); throws
// fem::MeshError, naming the line and the cause, for a file it refuses.
Body body_from_gmsh_file(const std::string& path, const BodyDescription& description);

}  // namespace FEMCOURSE_ABI
}  // namespace femcourse
