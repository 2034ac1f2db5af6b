#include "femcourse/simulator.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <deque>
#include <stdexcept>
#include <utility>

#include "chapters/registry.hpp"
#include "common/deformation.hpp"
#include "common/mesh.hpp"
#include "common/model.hpp"
#include "common/scene.hpp"
#include "common/stepper.hpp"
#include "common/threads.hpp"
#include "femcourse/node_forces.hpp"

namespace femcourse {
inline namespace FEMCOURSE_ABI {
namespace {

constexpr int kMostSubsteps = 1000;  // more is a typo: a step() of a thousand steps' cost

[[noreturn]] void refuse(const std::string& problem) {
  throw std::invalid_argument("femcourse::Body: " + problem);
}

std::string node_name(long long i) { return "node " + std::to_string(i); }
std::string tet_name(std::size_t e) { return "tetrahedron " + std::to_string(e); }

// The checks make_mesh does not make because it repairs instead (it flips inverted
// tetrahedra and drops unused nodes, which would renumber the caller's nodes): here the
// caller's numbering is the interface, so both are refused.
void check_connectivity(const BodyDescription& d, Eigen::Index num_nodes) {
  if (d.rest_positions.empty() || d.rest_positions.size() % 3 != 0)
    refuse("rest_positions holds " + std::to_string(d.rest_positions.size()) +
           " values, not 3 per node");
  if (d.tetrahedra.empty() || d.tetrahedra.size() % 4 != 0)
    refuse("tetrahedra holds " + std::to_string(d.tetrahedra.size()) +
           " indices, not 4 per element");
  std::vector<bool> used(static_cast<std::size_t>(num_nodes), false);
  for (std::size_t k = 0; k < d.tetrahedra.size(); ++k) {
    const int n = d.tetrahedra[k];
    if (n < 0 || n >= num_nodes)
      refuse(tet_name(k / 4) + " refers to " + node_name(n) + ", which does not exist (" +
             std::to_string(num_nodes) + " nodes)");
    used[static_cast<std::size_t>(n)] = true;
  }
  for (std::size_t i = 0; i < used.size(); ++i)
    if (!used[i]) refuse(node_name(static_cast<long long>(i)) + " belongs to no tetrahedron");
}

void check_orientation(const fem::TetMesh& mesh) {
  for (std::size_t e = 0; e < mesh.tets.size(); ++e) {
    const Eigen::Vector4i& t = mesh.tets[e];
    Eigen::Matrix3d Dm;
    for (int i = 0; i < 3; ++i) Dm.col(i) = mesh.X.col(t[i + 1]) - mesh.X.col(t[0]);
    if (Dm.determinant() < 0.0)
      refuse(tet_name(e) + " is inverted (negative volume): swap two of its nodes");
  }
}

fem::TetMesh mesh_of(const BodyDescription& d) {
  const auto num_nodes = static_cast<Eigen::Index>(d.rest_positions.size() / 3);
  check_connectivity(d, num_nodes);
  const Eigen::Matrix3Xd X =
      Eigen::Map<const Eigen::Matrix3Xd>(d.rest_positions.data(), 3, num_nodes);
  std::vector<Eigen::Vector4i> tets(d.tetrahedra.size() / 4);
  for (std::size_t e = 0; e < tets.size(); ++e)
    tets[e] = Eigen::Map<const Eigen::Vector4i>(d.tetrahedra.data() + 4 * e);
  {
    // Orientation first, on the caller's arrays: make_mesh would flip an inverted element.
    fem::TetMesh unchecked;
    unchecked.X = X;
    unchecked.tets = tets;
    if (X.allFinite()) check_orientation(unchecked);
  }
  try {
    return fem::make_mesh(X, std::move(tets), "femcourse::Body");  // NaN, zero volume
  } catch (const fem::MeshError& e) {
    throw std::invalid_argument(e.what());
  }
}

Eigen::Vector3d vector_of(const std::array<double, 3>& a) { return {a[0], a[1], a[2]}; }

fem::NodeConstraint constraint_of(const Constraint& c, int num_nodes) {
  if (c.node < 0 || c.node >= num_nodes)
    refuse("a constraint names " + node_name(c.node) + ", which does not exist (" +
           std::to_string(num_nodes) + " nodes)");
  const Eigen::Vector3d direction = vector_of(c.direction);
  const Eigen::Vector3d velocity = vector_of(c.velocity);
  if (!direction.allFinite() || !velocity.allFinite())
    refuse("the constraint on " + node_name(c.node) +
           " has a NaN or infinite direction or velocity");
  if (c.kind != Constraint::Kind::Fixed && !(direction.norm() > 0.0))
    refuse("the constraint on " + node_name(c.node) + " has a zero direction");
  switch (c.kind) {
    case Constraint::Kind::Plane:
      return fem::NodeConstraint::plane(c.node, direction);
    case Constraint::Kind::Line:
      return fem::NodeConstraint::line(c.node, direction);
    case Constraint::Kind::Fixed:
      break;
  }
  return fem::NodeConstraint::fixed(c.node, velocity);
}

fem::Scene scene_of(const BodyDescription& d, fem::TetMesh mesh) {
  fem::Scene scene;
  scene.name = "body";
  scene.material = {d.youngs_modulus, d.poisson_ratio, d.density};
  scene.damping = {d.damping_alpha, d.damping_beta};
  if (d.substeps < 1 || d.substeps > kMostSubsteps)
    refuse("substeps is " + std::to_string(d.substeps) + ": 1 to " + std::to_string(kMostSubsteps));
  scene.dt = d.time_step / d.substeps;
  scene.gravity = vector_of(d.gravity);
  for (const Constraint& c : d.constraints)
    scene.constraints.push_back(constraint_of(c, mesh.num_nodes()));
  scene.mesh = std::move(mesh);
  fem::validate(scene);
  return scene;
}

fem::SolverSettings solver_of(const BodyDescription& d) {
  if (!(d.solver_tolerance > 0.0) || d.solver_max_iterations <= 0)
    refuse("solver_tolerance and solver_max_iterations must be positive");
  // At 1 or more the solve stops before its first iteration (||r|| <= ||b|| at the start):
  // the body would never move, silently.
  if (!(d.solver_tolerance < 1.0))
    refuse("solver_tolerance is " + std::to_string(d.solver_tolerance) +
           ": it must lie in (0, 1) (at 1 or more CG stops before its first iteration)");
  return {d.solver_tolerance, d.solver_max_iterations};
}

const fem::ChapterInfo& chapter_of(const std::string& name) {
  return name.empty() ? fem::latest_chapter() : fem::find_chapter(name);
}

void check_node(int node, int num_nodes, const char* what) {
  if (node < 0 || node >= num_nodes)
    refuse(std::string(what) + " names " + node_name(node) + ", which does not exist (" +
           std::to_string(num_nodes) + " nodes)");
}

// OMP_NUM_THREADS in a form both OpenMP runtimes read alike, before the body's first OpenMP
// call: LLVM's libomp aborts the process at its first call on "1.5", "" or "+2" (GCC's ignores
// them), so an app's first step would end in SIGABRT where a program of the course refuses.
void check_thread_environment() {
  try {
    fem::thread_environment_count();
  } catch (const std::invalid_argument& e) {
    refuse(e.what());
  }
}

void check_threads(int threads) {
  check_thread_environment();
  if (threads < 0) refuse("threads is " + std::to_string(threads) + ": 0 (automatic) or more");
  if (threads > 1 && !fem::openmp_enabled())
    refuse("threads is " + std::to_string(threads) + ", but the library has no OpenMP: 0 or 1");
  if (threads > 1) fem::check_thread_count(threads);  // throws above the sane limit
}

// What to change when a step diverged, by its reason (fem::divergence), in the API's terms.
std::string advice_for(const std::string& reason) {
  if (reason.find("did not converge") != std::string::npos)
    return "raise solver_max_iterations, keep poisson_ratio further from 0.5, or shorten "
           "time_step";
  if (reason.find("residual is not finite") != std::string::npos)
    return "the system overflows: check youngs_modulus, the damping and time_step for "
           "absurd values";
  return "shorten time_step, or check youngs_modulus, density, the damping and the forces "
         "for absurd values";
}

// The thread count of one step, set on the thread that steps (OpenMP's count is per thread),
// and that thread's own count restored after.
class StepThreads {
 public:
  explicit StepThreads(int threads) : previous_(fem::max_threads()), set_(threads > 0) {
    if (set_) fem::set_threads(threads);
  }
  ~StepThreads() {
    if (set_) fem::set_threads(previous_);
  }
  StepThreads(const StepThreads&) = delete;
  StepThreads& operator=(const StepThreads&) = delete;

 private:
  int previous_;
  bool set_;
};

constexpr std::size_t kKeptWarnings = 64;

}  // namespace

StepDiverged::StepDiverged(long long k, const std::string& why, const std::string& advice)
    : std::runtime_error("femcourse::Body: the simulation diverged at step " + std::to_string(k) +
                         " (" + why + "): " + advice),
      step(k),
      reason(why) {}

struct Body::Impl {
  fem::Scene scene;  // first: the stepper is built from it and may keep a reference
  StepperFactory make;
  std::unique_ptr<fem::Stepper> stepper;
  int threads_used = 0;  // the last step's team
  fem::State state;
  Eigen::VectorXd previous_v;  // before the last step: the reactions' dv
  fem::SolverSettings solver;
  std::vector<fem::ExternalForce> forces;  // reused: set_forces allocates once
  bool forces_set = false;                 // set_forces was called: forces replace the scene's
  StepProfile profile;
  std::string chapter;
  long long steps = 0;  // step() calls
  int substeps = 1;
  bool warned_impact = false;  // the floor's inverting impact, reported once
  int threads = 0;             // as asked: 0 automatic
  // The constraints are composed from three sources (compose_constraints).
  std::vector<fem::NodeConstraint> own;  // the description's, for the body's life
  std::vector<int> grabbed;
  Eigen::Vector3d grab_velocity = Eigen::Vector3d::Zero();
  bool floor_on = false;
  Eigen::Vector3d floor_point = Eigen::Vector3d::Zero(), floor_normal = Eigen::Vector3d::UnitZ();
  double floor_friction = 0.0;
  std::vector<int> contacts;
  std::vector<int> stuck;
  std::vector<fem::NodeConstraint> composed;  // compose_constraints' storage, reused   // the
                                              // contacts friction holds still, sorted
  std::vector<char> owned;                    // per node: has a constraint of its own
  std::vector<std::array<int, 3>> surface;
  // The forces' model, made on first need (reactions, the floor, elastic_forces), and the
  // forces at the positions of one state, node by node (femcourse/node_forces.hpp): each
  // element computed once per state and shared by every read-out of it (the floor's release
  // test and friction, reactions, elastic_forces).
  mutable std::unique_ptr<fem::Model> model;
  mutable std::unique_ptr<detail::NodeForces> node_forces;
  long long positions_version = 0;  // counts the changes of state.x
  mutable long long forces_version = -1;
  mutable std::vector<NodeForce> reactions_out;  // the read-outs' storage, reused
  mutable std::vector<double> elastic_out;
  mutable std::unique_ptr<fem::DeformationProbe> probe;
  std::function<void(const std::string&)> warning_handler;
  std::deque<std::string> warnings;

  Impl(fem::Scene s, StepperFactory factory, const fem::SolverSettings& settings, std::string id)
      : scene(std::move(s)), make(std::move(factory)), solver(settings), chapter(std::move(id)) {
    own = scene.constraints;
    owned.assign(static_cast<std::size_t>(scene.mesh.num_nodes()), 0);
    for (const fem::NodeConstraint& c : own) owned[static_cast<std::size_t>(c.node)] = 1;
    for (const Eigen::Vector3i& t : scene.mesh.boundary) surface.push_back({t[0], t[1], t[2]});
    stepper = make(scene, solver);
    state = fem::rest_state(scene);
    previous_v = state.v;
  }

  const std::vector<fem::ExternalForce>& current_forces() const {
    return forces_set ? forces : scene.external_forces;
  }
  bool is_grabbed(int node) const {
    return std::find(grabbed.begin(), grabbed.end(), node) != grabbed.end();
  }
  const std::vector<fem::NodeConstraint>& compose_constraints();
  void apply_constraints(const std::vector<fem::NodeConstraint>& constraints);
  // A new stepper from the scene: no history (warm starts, rotations, a lagged hierarchy), so
  // that a saved state alone decides what follows; the read-outs' rotations start over too.
  void restart_stepper() {
    rebuild_stepper();
    if (node_forces) node_forces->restart();
  }
  void rebuild_stepper();
  void replace_contacts(std::vector<int> next, std::vector<int> next_stuck = {});
  bool is_stuck(int node) const { return std::binary_search(stuck.begin(), stuck.end(), node); }
  detail::NodeForces& read_forces() const;  // elastic + gravity at state.x, node by node
  // `decides`: the body's own floor decides by it (NodeForces::Reader::floor).
  Eigen::Vector3d reaction(int node, bool decides = false) const;
  void sub_step();
  void update_floor();
  bool land_free_nodes();
  bool release_pulled_contacts();
  bool apply_friction();
  void warn_if_impact_inverts();
  void check_restorable(const BodyState& saved) const;
  static void receive_warning(void* self, const std::string& message);
  // Inside the step's thread scope: the team its stepper recorded, else the count in force
  // for a stepper that threads without saying, else one.
  int team_of_last_step() const {
    const int team = stepper->threads_used();
    if (team > 0) return team;
    return stepper->uses_threads() ? fem::max_threads() : 1;
  }
  void set_floor(bool on, const Eigen::Vector3d& point, const Eigen::Vector3d& normal,
                 double friction) {
    floor_on = on;
    floor_point = point;
    floor_normal = normal;
    floor_friction = friction;
  }
};

// Into `composed`, whose storage is kept: a drag (move_grabbed) or a contact that sticks
// allocates nothing once it has held as many constraints.
const std::vector<fem::NodeConstraint>& Body::Impl::compose_constraints() {
  std::vector<fem::NodeConstraint>& all = composed;
  all.clear();
  for (const fem::NodeConstraint& c : own)
    if (!is_grabbed(c.node)) all.push_back(c);
  for (const int node : grabbed) all.push_back(fem::NodeConstraint::fixed(node, grab_velocity));
  for (const int node : contacts)
    all.push_back(is_stuck(node) ? fem::NodeConstraint::fixed(node)
                                 : fem::NodeConstraint::plane(node, floor_normal));
  return all;
}

// In place when the stepper can (the scene's copy assigned into its own storage); else a new
// stepper from the scene (the slow path). Either way a throw leaves the scene's constraints
// and the stepper as they were.
void Body::Impl::apply_constraints(const std::vector<fem::NodeConstraint>& constraints) {
  if (stepper->can_change_constraints()) {
    stepper->set_constraints(constraints);
    scene.constraints.assign(constraints.begin(), constraints.end());
    return;
  }
  std::vector<fem::NodeConstraint> previous = constraints;
  std::swap(scene.constraints, previous);
  try {
    rebuild_stepper();
  } catch (...) {
    std::swap(scene.constraints, previous);
    throw;
  }
}

void Body::Impl::rebuild_stepper() {
  std::unique_ptr<fem::Stepper> rebuilt = make(scene, solver);
  rebuilt->set_external_forces(current_forces());
  stepper = std::move(rebuilt);
}

// The floor's contacts (those of them that stick), and the constraints with them; a throw
// leaves them as they were.
void Body::Impl::replace_contacts(std::vector<int> next, std::vector<int> next_stuck) {
  std::sort(next_stuck.begin(), next_stuck.end());
  std::swap(contacts, next);
  std::swap(stuck, next_stuck);
  try {
    apply_constraints(compose_constraints());
  } catch (...) {
    std::swap(contacts, next);
    std::swap(stuck, next_stuck);
    throw;
  }
}

detail::NodeForces& Body::Impl::read_forces() const {
  if (!model) {
    model = std::make_unique<fem::Model>(scene);
    node_forces = std::make_unique<detail::NodeForces>(*model, scene);
  }
  if (forces_version != positions_version) {
    node_forces->new_positions();
    forces_version = positions_version;
  }
  return *node_forces;
}

// m dv/dt - f(x) - f_ext + alpha m v: what the constraint added to the node's momentum.
Eigen::Vector3d Body::Impl::reaction(int node, bool decides) const {
  const Eigen::Vector3d f = read_forces().at(
      node, state.x, decides ? detail::NodeForces::Reader::floor : detail::NodeForces::Reader::app);
  const Eigen::Index i = 3 * node;
  const Eigen::Vector3d m = model->lumped_mass.segment<3>(i);
  const Eigen::Vector3d v = state.v.segment<3>(i);
  const Eigen::Vector3d dv = v - previous_v.segment<3>(i);
  Eigen::Vector3d f_ext = Eigen::Vector3d::Zero();
  for (int r = 0; r < 3; ++r) f_ext[r] = stepper->external_forces().coeff(i + r);
  return m.cwiseProduct(dv) / scene.dt - f - f_ext + scene.damping.alpha * m.cwiseProduct(v);
}

// Contacts whose floor pulls are let go; true when one was.
bool Body::Impl::release_pulled_contacts() {
  const auto pulling = [&](int node) { return reaction(node, true).dot(floor_normal) < 0.0; };
  const auto end = std::remove_if(contacts.begin(), contacts.end(), pulling);
  if (end == contacts.end()) return false;
  contacts.erase(end, contacts.end());
  const auto gone = [&](int node) {
    return std::find(contacts.begin(), contacts.end(), node) == contacts.end();
  };
  stuck.erase(std::remove_if(stuck.begin(), stuck.end(), gone), stuck.end());
  return true;
}

// Coulomb friction on the contacts that stay (set_floor), by the reaction each needs, which
// reaction() reads from its velocity: a velocity change dv moves it by c dv, c = m (1/dt +
// alpha). A stuck contact whose tangential reaction exceeds friction * R_n slides from the next
// step. A sliding one sticks (its velocity along the floor taken away) where the reaction that
// leaves stays inside the cone |R_t| <= friction * R_n; else it loses along the floor what the
// cone allows in a step, friction * R_n / c. True when a contact changed between the two.
// Each node's reaction is taken before its velocity changes.
bool Body::Impl::apply_friction() {
  if (floor_friction == 0.0) return false;
  bool changed = false;
  const auto tangential = [&](const Eigen::Vector3d& f) {
    return f - floor_normal.dot(f) * floor_normal;
  };
  for (const int node : contacts) {
    const Eigen::Vector3d r = reaction(node, true);
    const double cone = floor_friction * std::max(0.0, r.dot(floor_normal));
    if (is_stuck(node)) {
      if (tangential(r).norm() <= cone) continue;
      stuck.erase(std::lower_bound(stuck.begin(), stuck.end(), node));
      changed = true;
      continue;
    }
    auto v = state.v.segment<3>(3 * node);
    const Eigen::Vector3d along = tangential(v);
    const double speed = along.norm(), mass = model->lumped_mass[3 * node];
    const double c = mass * (1.0 / scene.dt + scene.damping.alpha);
    if (tangential(r - c * along).norm() <= cone) {
      v -= along;
      stuck.insert(std::upper_bound(stuck.begin(), stuck.end(), node), node);
      changed = true;
    } else if (speed > 0.0) {
      v -= std::min(1.0, cone / (c * speed)) * along;
    }
  }
  return changed;
}

// Free nodes below the floor put on it, their velocity into it removed; true when one was.
bool Body::Impl::land_free_nodes() {
  bool landed = false;
  for (int node = 0; node < scene.mesh.num_nodes(); ++node) {
    const auto n = static_cast<std::size_t>(node);
    auto x = state.x.segment<3>(3 * node);
    const double depth = floor_normal.dot(x - floor_point);
    if (depth >= 0.0 || owned[n] || is_grabbed(node) ||
        std::find(contacts.begin(), contacts.end(), node) != contacts.end())
      continue;
    x -= depth * floor_normal;
    ++positions_version;
    auto v = state.v.segment<3>(3 * node);
    v -= std::min(0.0, floor_normal.dot(v)) * floor_normal;
    contacts.push_back(node);
    landed = true;
  }
  return landed;
}

// The floor's active set after a step: free nodes below it put on it first, then, at the
// positions that leaves, contacts whose floor pulls are let go and friction on the others.
// In that order the reactions the floor decides by are those reactions() reports (each
// element's forces computed once for both), and a node that lands meets friction in its landing
// step (the impact's push limits its slide, as an impulse would).
void Body::Impl::update_floor() {
  if (!floor_on) return;
  const bool landed = land_free_nodes();
  bool changed = landed;
  if (!contacts.empty()) {
    read_forces().prepare(
        contacts, [](int node) { return node; }, state.x, detail::NodeForces::Reader::floor);
    changed = release_pulled_contacts() || changed;
    changed = apply_friction() || changed;
  }
  if (changed) apply_constraints(compose_constraints());
  if (landed) warn_if_impact_inverts();
}

// An impact the step was too long for: the nodes put on the floor squash the elements above
// them inside out. Checked on the steps that put nodes on the floor only (a pass over the
// elements), and said once.
void Body::Impl::warn_if_impact_inverts() {
  if (warned_impact) return;
  if (!probe) probe = std::make_unique<fem::DeformationProbe>(scene);
  const fem::DeformationCheck c = probe->check(state);
  if (c.inverted == 0) return;
  warned_impact = true;
  receive_warning(this, "femcourse::Body: step " + std::to_string(steps) + ": " +
                            std::to_string(c.inverted) + " of " + std::to_string(c.elements) +
                            " elements inverted as the body hit the floor (reported once): "
                            "raise BodyDescription::substeps (now " +
                            std::to_string(substeps) + "), or shorten time_step");
}

void Body::Impl::receive_warning(void* self, const std::string& message) {
  Impl& b = *static_cast<Impl*>(self);
  if (b.warning_handler) return b.warning_handler(message);
  if (b.warnings.size() == kKeptWarnings) b.warnings.pop_front();
  b.warnings.push_back(message);
}

Body::Body(const BodyDescription& d) : Body(d, StepperFactory{}) {}

Body::Body(const BodyDescription& d, const StepperFactory& make_stepper) {
  const fem::SolverSettings solver = solver_of(d);
  check_threads(d.threads);
  fem::Scene scene = scene_of(d, mesh_of(d));
  if (make_stepper) {
    impl_ = std::make_unique<Impl>(std::move(scene), make_stepper, solver, "custom");
  } else {
    const fem::ChapterInfo& info = chapter_of(d.chapter);
    impl_ = std::make_unique<Impl>(std::move(scene), info.make, solver, info.id);
  }
  impl_->threads = d.threads;
  impl_->substeps = d.substeps;
}

Body::Body(fem::Scene scene, const fem::SolverSettings& solver, const std::string& chapter) {
  check_thread_environment();
  fem::validate(scene);
  const fem::ChapterInfo& info = chapter_of(chapter);
  impl_ = std::make_unique<Impl>(std::move(scene), info.make, solver, info.id);
}

Body::~Body() = default;
Body::Body(Body&&) noexcept = default;
Body& Body::operator=(Body&&) noexcept = default;

Body::Impl& Body::impl() { return const_cast<Impl&>(static_cast<const Body&>(*this).impl()); }

const Body::Impl& Body::impl() const {
  if (!impl_)
    throw std::logic_error(
        "femcourse::Body: this body was moved from: assign a Body to it "
        "before using it");
  return *impl_;
}

void Body::step() {
  Impl& b = impl();
  ++b.steps;
  for (int k = 0; k < b.substeps; ++k) b.sub_step();
}

void Body::Impl::sub_step() {
  Impl& b = *this;
  b.previous_v = b.state.v;
  {
    const StepThreads team(b.threads > 0                              ? b.threads
                           : scene.mesh.num_nodes() < kSmallBodyNodes ? 1
                                                                      : 0);
    // An asked count is the one that steps: no adaptive team below it (common/threads.hpp).
    const fem::AskedThreadsScope asked(b.threads > 0);
    const fem::WarningSinkScope sink(&Impl::receive_warning, &b);
    b.stepper->step(b.state);
    ++b.positions_version;
    b.threads_used = b.team_of_last_step();
  }
  const fem::StepProfile& p = b.stepper->profile();
  b.profile = {p.forces.seconds,    p.dfdx.seconds, p.compose.seconds,  p.constraints.seconds,
               p.solve.seconds,     p.step.seconds, p.step.allocations, p.cg_iterations,
               p.relative_residual, p.converged};
  if (const char* why = fem::divergence(b.state, p))
    throw StepDiverged(b.steps, why, advice_for(why));
  b.update_floor();
}

void Body::set_forces(const std::vector<NodeForce>& forces) {
  Impl& b = impl();
  for (const NodeForce& f : forces) {  // first, so that a refused list changes nothing
    check_node(f.node, num_nodes(), "set_forces");
    if (!vector_of(f.force).allFinite())
      refuse("set_forces: the force on " + node_name(f.node) + " is not finite");
  }
  b.forces.clear();  // keeps the capacity
  for (const NodeForce& f : forces) b.forces.push_back({f.node, vector_of(f.force)});
  b.stepper->set_external_forces(b.forces);
  b.forces_set = true;
}

int Body::num_nodes() const { return impl().scene.mesh.num_nodes(); }
int Body::num_tetrahedra() const { return impl().scene.mesh.num_tets(); }
const double* Body::positions() const { return impl().state.x.data(); }
const double* Body::velocities() const { return impl().state.v.data(); }

std::array<double, 3> Body::position(int node) const {
  if (node < 0 || node >= num_nodes())
    throw std::out_of_range("femcourse::Body::position: " + node_name(node) + " does not exist");
  const double* x = positions() + 3 * node;
  return {x[0], x[1], x[2]};
}

double Body::time() const {
  return static_cast<double>(impl().steps) * impl().substeps * impl().scene.dt;
}
const StepProfile& Body::profile() const { return impl().profile; }
const std::string& Body::chapter() const { return impl().chapter; }

void Body::set_chapter(const std::string& chapter) {
  Impl& b = impl();
  const fem::ChapterInfo& info = chapter_of(chapter);
  std::unique_ptr<fem::Stepper> next = info.make(b.scene, b.solver);
  next->set_external_forces(b.current_forces());
  // Nothing above changed the body: from here on nothing throws.
  b.stepper = std::move(next);
  b.make = info.make;
  b.chapter = info.id;
}

int Body::threads() const { return impl().threads; }
int Body::threads_used() const { return impl().threads_used; }

void Body::set_threads(int threads) {
  Impl& b = impl();
  check_threads(threads);
  b.threads = threads;
}

void Body::grab(const std::vector<int>& nodes, const std::array<double, 3>& velocity) {
  Impl& b = impl();
  for (const int node : nodes) check_node(node, num_nodes(), "grab");
  if (!vector_of(velocity).allFinite()) refuse("grab: the velocity is not finite");
  std::vector<int> grabbed = nodes;
  std::sort(grabbed.begin(), grabbed.end());
  grabbed.erase(std::unique(grabbed.begin(), grabbed.end()), grabbed.end());
  // A grabbed node leaves the floor.
  const auto held = [&](int n) { return std::binary_search(grabbed.begin(), grabbed.end(), n); };
  std::vector<int> contacts = b.contacts, stuck = b.stuck;
  contacts.erase(std::remove_if(contacts.begin(), contacts.end(), held), contacts.end());
  stuck.erase(std::remove_if(stuck.begin(), stuck.end(), held), stuck.end());
  std::swap(b.grabbed, grabbed);
  std::swap(b.contacts, contacts);
  std::swap(b.stuck, stuck);
  const Eigen::Vector3d previous_velocity = b.grab_velocity;
  b.grab_velocity = vector_of(velocity);
  try {
    b.apply_constraints(b.compose_constraints());
  } catch (...) {
    std::swap(b.grabbed, grabbed);
    std::swap(b.contacts, contacts);
    std::swap(b.stuck, stuck);
    b.grab_velocity = previous_velocity;
    throw;
  }
}

// The same nodes at another velocity: no new list of nodes, the constraints composed into
// their kept storage, so that a drag allocates nothing per frame (chapters that change their
// constraints in place).
void Body::move_grabbed(const std::array<double, 3>& velocity) {
  Impl& b = impl();
  if (!vector_of(velocity).allFinite()) refuse("move_grabbed: the velocity is not finite");
  const Eigen::Vector3d previous = b.grab_velocity;
  b.grab_velocity = vector_of(velocity);
  try {
    b.apply_constraints(b.compose_constraints());
  } catch (...) {
    b.grab_velocity = previous;
    throw;
  }
}

void Body::release() { grab({}); }
const std::vector<int>& Body::grabbed() const { return impl().grabbed; }

void Body::set_floor(const std::array<double, 3>& point, const std::array<double, 3>& normal,
                     double friction) {
  Impl& b = impl();
  const Eigen::Vector3d p = vector_of(point), n = vector_of(normal);
  if (!p.allFinite() || !n.allFinite() || !(n.norm() > 0.0))
    refuse("set_floor: the point and the normal must be finite, the normal not zero");
  if (!std::isfinite(friction) || friction < 0.0)
    refuse("set_floor: the friction coefficient must be finite and not negative, not " +
           std::to_string(friction));
  // A floor moved or tilted under a resting body lets its contacts go: the next step finds
  // them against the new plane (held on the old one, they would stay where it was). Without
  // friction no contact sticks.
  const bool moved = b.floor_on && (p != b.floor_point || n.normalized() != b.floor_normal);
  if (moved && !b.contacts.empty())
    b.replace_contacts({});
  else if (friction == 0.0 && !b.stuck.empty())
    b.replace_contacts(b.contacts);
  b.set_floor(true, p, n.normalized(), friction);
}

void Body::remove_floor() {
  Impl& b = impl();
  b.replace_contacts({});
  b.floor_on = false;
}

const std::vector<int>& Body::floor_contacts() const { return impl().contacts; }
bool Body::changes_constraints_in_place() const { return impl().stepper->can_change_constraints(); }
const std::vector<std::array<int, 3>>& Body::surface() const { return impl().surface; }

const std::vector<NodeForce>& Body::reactions() const {
  const Impl& b = impl();
  b.read_forces().prepare(
      b.scene.constraints, [](const fem::NodeConstraint& c) { return c.node; }, b.state.x,
      detail::NodeForces::Reader::app);
  b.reactions_out.clear();  // keeps its capacity
  for (const fem::NodeConstraint& c : b.scene.constraints) {
    const Eigen::Vector3d r = b.reaction(c.node);
    b.reactions_out.push_back({c.node, {r[0], r[1], r[2]}});
  }
  return b.reactions_out;
}

const std::vector<double>& Body::elastic_forces() const {
  const Impl& b = impl();
  const Eigen::VectorXd& forces =
      b.read_forces().all(b.state.x);  // makes the model: before gravity
  b.elastic_out.resize(static_cast<std::size_t>(forces.size()));
  Eigen::Map<Eigen::VectorXd>(b.elastic_out.data(), forces.size()) =
      forces - b.model->gravity_force;
  return b.elastic_out;
}

DeformationStatus Body::check_deformation() const {
  const Impl& b = impl();
  if (!b.probe) b.probe = std::make_unique<fem::DeformationProbe>(b.scene);
  const fem::DeformationCheck c = b.probe->check(b.state);
  const fem::DeformationLimits limits;
  const bool plausible =
      c.largest_stretch < limits.stretch && c.inverted <= limits.inverted_share * c.elements;
  return {c.inverted, c.largest_stretch, plausible};
}

void Body::set_warning_handler(std::function<void(const std::string&)> handler) {
  impl().warning_handler = std::move(handler);
}

std::vector<std::string> Body::take_warnings() {
  Impl& b = impl();
  std::vector<std::string> out(b.warnings.begin(), b.warnings.end());
  b.warnings.clear();
  return out;
}

BodyState Body::save_state() {
  Impl& b = impl();
  b.restart_stepper();
  const fem::State& s = b.state;
  const auto array = [](const Eigen::Vector3d& v) {
    return std::array<double, 3>{v[0], v[1], v[2]};
  };
  return {{s.x.data(), s.x.data() + s.x.size()},
          {s.v.data(), s.v.data() + s.v.size()},
          b.steps,
          b.contacts,
          b.floor_on,
          array(b.floor_point),
          array(b.floor_normal),
          b.floor_friction,
          b.stuck};
}

namespace {

bool all_finite(const std::vector<double>& values) {
  return std::all_of(values.begin(), values.end(), [](double v) { return std::isfinite(v); });
}

}  // namespace

// Everything checked before anything changes, each refusal in the state's own terms (the
// caller's node numbers, not the stepper's).
void Body::Impl::check_restorable(const BodyState& saved) const {
  const auto values = static_cast<std::size_t>(state.x.size());
  const int nodes = scene.mesh.num_nodes();
  if (saved.positions.size() != values || saved.velocities.size() != values)
    refuse("restore_state: the state holds " + std::to_string(saved.positions.size()) +
           " position and " + std::to_string(saved.velocities.size()) +
           " velocity values, the body needs " + std::to_string(values) + " of each (3 per node, " +
           std::to_string(nodes) + " nodes)");
  if (!all_finite(saved.positions) || !all_finite(saved.velocities))
    refuse("restore_state: the state holds a NaN or infinite position or velocity");
  if (!saved.floor && !saved.floor_contacts.empty())
    refuse("restore_state: the state holds " + std::to_string(saved.floor_contacts.size()) +
           " floor contacts but no floor (BodyState::floor is false): give its floor, or no "
           "contacts");
  const Eigen::Vector3d normal = vector_of(saved.floor_normal);
  if (saved.floor &&
      (!vector_of(saved.floor_point).allFinite() || !normal.allFinite() || !(normal.norm() > 0.0)))
    refuse(
        "restore_state: the state's floor point and normal must be finite, the normal not "
        "zero");
  if (saved.floor && (!std::isfinite(saved.floor_friction) || saved.floor_friction < 0.0))
    refuse("restore_state: the state's floor friction must be finite and not negative");
  std::vector<int> stuck = saved.floor_stuck;
  std::sort(stuck.begin(), stuck.end());
  for (std::size_t k = 0; k < stuck.size(); ++k) {
    const int node = stuck[k];
    if (std::find(saved.floor_contacts.begin(), saved.floor_contacts.end(), node) ==
        saved.floor_contacts.end())
      refuse("restore_state: a stuck floor contact, " + node_name(node) +
             ", is not among the floor contacts");
    if (k > 0 && stuck[k - 1] == node)
      refuse("restore_state: the stuck floor contacts name " + node_name(node) + " twice");
  }
  std::vector<char> seen(static_cast<std::size_t>(nodes), 0);
  for (const int node : saved.floor_contacts) {
    check_node(node, nodes, "restore_state: a floor contact");
    const auto n = static_cast<std::size_t>(node);
    if (seen[n]++) refuse("restore_state: the floor contacts name " + node_name(node) + " twice");
    if (owned[n] || is_grabbed(node))
      refuse("restore_state: a floor contact names " + node_name(node) + ", which " +
             (owned[n] ? "has a constraint of its own" : "is grabbed") +
             ": the floor holds free nodes only");
  }
}

void Body::restore_state(const BodyState& saved) {
  Impl& b = impl();
  b.check_restorable(saved);
  const bool was_on = b.floor_on;
  const Eigen::Vector3d point = b.floor_point, normal = b.floor_normal;
  const double friction = b.floor_friction;
  b.set_floor(saved.floor, vector_of(saved.floor_point),
              saved.floor ? vector_of(saved.floor_normal).normalized() : normal,
              saved.floor ? saved.floor_friction : friction);
  try {
    b.replace_contacts(saved.floor_contacts, saved.floor_stuck);
  } catch (...) {
    b.set_floor(was_on, point, normal, friction);
    throw;
  }
  b.restart_stepper();  // as save_state did: no history of the steps since
  b.state.x = Eigen::Map<const Eigen::VectorXd>(saved.positions.data(), b.state.x.size());
  b.state.v = Eigen::Map<const Eigen::VectorXd>(saved.velocities.data(), b.state.v.size());
  ++b.positions_version;
  b.previous_v = b.state.v;
  b.steps = saved.steps;
}

void Body::set_state(const fem::State& state) {
  Impl& b = impl();
  if (state.x.size() != b.state.x.size() || state.v.size() != b.state.v.size())
    refuse("set_state: the state has " + std::to_string(state.x.size() / 3) + " nodes, the body " +
           std::to_string(num_nodes()));
  b.state.x = state.x;
  b.state.v = state.v;
  ++b.positions_version;
}

const fem::Scene& Body::scene() const { return impl().scene; }
const fem::State& Body::state() const { return impl().state; }
const fem::Stepper& Body::stepper() const { return *impl().stepper; }

Body body_from_gmsh_file(const std::string& path, const BodyDescription& description) {
  fem::TetMesh mesh = fem::load_mesh(path);  // the course's reader, common/msh_read.cpp
  BodyDescription d = description;
  d.rest_positions.assign(mesh.X.data(), mesh.X.data() + mesh.X.size());
  d.tetrahedra.clear();
  for (const Eigen::Vector4i& t : mesh.tets)
    d.tetrahedra.insert(d.tetrahedra.end(), t.data(), t.data() + 4);
  return Body(d);
}

}  // namespace FEMCOURSE_ABI
}  // namespace femcourse
