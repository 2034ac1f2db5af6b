#include "femcourse/simulator.hpp"

#include <Eigen/LU>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "chapters/registry.hpp"
#include "common/mesh.hpp"
#include "common/scene.hpp"
#include "common/stepper.hpp"

namespace femcourse {
namespace {

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
  scene.dt = d.time_step;
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
  return {d.solver_tolerance, d.solver_max_iterations};
}

const fem::ChapterInfo& chapter_of(const std::string& name) {
  return name.empty() ? fem::latest_chapter() : fem::find_chapter(name);
}

}  // namespace

StepDiverged::StepDiverged(long long k, const std::string& why)
    : std::runtime_error("the simulation diverged at step " + std::to_string(k) + " (" + why +
                         "); try a smaller time step"),
      step(k),
      reason(why) {}

struct Body::Impl {
  fem::Scene scene;  // first: the stepper is built from it and may keep a reference
  std::unique_ptr<fem::Stepper> stepper;
  fem::State state;
  fem::SolverSettings solver;
  std::vector<fem::ExternalForce> forces;  // reused: set_forces allocates once
  bool forces_set = false;                 // set_forces was called: forces replace the scene's
  StepProfile profile;
  std::string chapter;
  long long steps = 0;

  Impl(fem::Scene s, const StepperFactory& make, const fem::SolverSettings& settings,
       std::string id)
      : scene(std::move(s)), solver(settings), chapter(std::move(id)) {
    stepper = make(scene, solver);
    state = fem::rest_state(scene);
  }
};

Body::Body(const BodyDescription& d) : Body(d, StepperFactory{}) {}

Body::Body(const BodyDescription& d, const StepperFactory& make_stepper) {
  const fem::SolverSettings solver = solver_of(d);
  fem::Scene scene = scene_of(d, mesh_of(d));
  if (make_stepper) {
    impl_ = std::make_unique<Impl>(std::move(scene), make_stepper, solver, "custom");
  } else {
    const fem::ChapterInfo& info = chapter_of(d.chapter);
    impl_ = std::make_unique<Impl>(std::move(scene), info.make, solver, info.id);
  }
}

Body::Body(fem::Scene scene, const fem::SolverSettings& solver, const std::string& chapter) {
  fem::validate(scene);
  const fem::ChapterInfo& info = chapter_of(chapter);
  impl_ = std::make_unique<Impl>(std::move(scene), info.make, solver, info.id);
}

Body::~Body() = default;
Body::Body(Body&&) noexcept = default;
Body& Body::operator=(Body&&) noexcept = default;

void Body::step() {
  Impl& b = *impl_;
  b.stepper->step(b.state);
  ++b.steps;
  const fem::StepProfile& p = b.stepper->profile();
  b.profile = {p.forces.seconds,    p.dfdx.seconds, p.compose.seconds,  p.constraints.seconds,
               p.solve.seconds,     p.step.seconds, p.step.allocations, p.cg_iterations,
               p.relative_residual, p.converged};
  if (const char* why = fem::divergence(b.state, p)) throw StepDiverged(b.steps, why);
}

void Body::set_forces(const std::vector<NodeForce>& forces) {
  Impl& b = *impl_;
  b.forces.clear();  // keeps the capacity
  for (const NodeForce& f : forces) b.forces.push_back({f.node, vector_of(f.force)});
  b.stepper->set_external_forces(b.forces);
  b.forces_set = true;
}

int Body::num_nodes() const { return impl_->scene.mesh.num_nodes(); }
int Body::num_tetrahedra() const { return impl_->scene.mesh.num_tets(); }
const double* Body::positions() const { return impl_->state.x.data(); }
const double* Body::velocities() const { return impl_->state.v.data(); }

std::array<double, 3> Body::position(int node) const {
  if (node < 0 || node >= num_nodes())
    throw std::out_of_range("femcourse::Body::position: " + node_name(node) + " does not exist");
  const double* x = positions() + 3 * node;
  return {x[0], x[1], x[2]};
}

double Body::time() const { return static_cast<double>(impl_->steps) * impl_->scene.dt; }
const StepProfile& Body::profile() const { return impl_->profile; }
const std::string& Body::chapter() const { return impl_->chapter; }
void Body::set_chapter(const std::string& chapter) {
  const fem::ChapterInfo& info = chapter_of(chapter);
  impl_->stepper = info.make(impl_->scene, impl_->solver);
  impl_->stepper->set_external_forces(impl_->forces_set ? impl_->forces
                                                        : impl_->scene.external_forces);
  impl_->chapter = info.id;
}

void Body::set_state(const fem::State& state) {
  if (state.x.size() != impl_->state.x.size() || state.v.size() != impl_->state.v.size())
    refuse("set_state: the state has " + std::to_string(state.x.size() / 3) + " nodes, the body " +
           std::to_string(num_nodes()));
  impl_->state.x = state.x;
  impl_->state.v = state.v;
}

const fem::Scene& Body::scene() const { return impl_->scene; }
const fem::State& Body::state() const { return impl_->state; }
const fem::Stepper& Body::stepper() const { return *impl_->stepper; }

Body body_from_gmsh_file(const std::string& path, const BodyDescription& description) {
  fem::TetMesh mesh = fem::load_mesh(path);  // femcourse::mesh_gmsh, else it throws
  BodyDescription d = description;
  d.rest_positions.assign(mesh.X.data(), mesh.X.data() + mesh.X.size());
  d.tetrahedra.clear();
  for (const Eigen::Vector4i& t : mesh.tets)
    d.tetrahedra.insert(d.tetrahedra.end(), t.data(), t.data() + 4);
  return Body(d);
}

}  // namespace femcourse
