// Chapter 11's lesson table: `fem_lessons node-order` (see lesson.hpp).
#include "chapters/11_node_order/lesson.hpp"

#include <algorithm>
#include <filesystem>
#include <iomanip>
#include <memory>
#include <sstream>
#include <string>

#include "chapters/11_node_order/stepper.hpp"
#include "common/cli.hpp"
#include "common/lesson.hpp"

namespace fem::ch11 {

namespace {

struct Run {
  std::string name;  // the order, as the table names it
  Scene scene;       // in the numbering of its mesh file
  Ordering ordering;
  std::unique_ptr<NodeOrderStepper> stepper;
  State state;
  std::vector<double> element_ms, iterations;
};

// The chapter's own orders on the scene, and gmsh's where fem-tools runs renumber-meshes wrote a
// copy of the mesh beside the generated meshes (meshes/generated/NAME_rcmk.msh, ...).
std::vector<Run> runs_for(const LessonRun& run) {
  std::vector<Run> runs;
  for (const Ordering o : {Ordering::original, Ordering::rcm, Ordering::morton})
    runs.push_back({ordering_name(o), run.scene, o, nullptr, {}, {}, {}});
  const std::filesystem::path file(run.scene.mesh.file);
  for (const char* method : {"rcmk", "hilbert", "metis"}) {
    const auto copy = file.parent_path().parent_path() / "meshes" / "generated" /
                      (file.stem().string() + "_" + method + ".msh");
    const auto beside = file.parent_path() / (file.stem().string() + "_" + method + ".msh");
    for (const auto& path : {copy, beside}) {
      if (!std::filesystem::exists(path)) continue;
      Scene scene = make_scene(run.scene.name, load_mesh(path.string()), run.scene.material);
      scene.dt = run.scene.dt;
      scene.damping = run.scene.damping;
      runs.push_back(
          {std::string("gmsh ") + method, std::move(scene), Ordering::file, nullptr, {}, {}, {}});
      break;
    }
  }
  return runs;
}

// One row: the order's measures of memory distance, and its times (1 thread, medians).
std::string row(Run& r) {
  const OrderQuality q =
      order_quality(renumbered(r.scene, r.stepper->order().node_order(), false).mesh);
  const auto& A = r.stepper->system_matrix();
  Eigen::VectorXd x = Eigen::VectorXd::Ones(3 * A.block_rows()), y(x.size());
  const double spmv = time_ms(
      50, [&] { A.multiply(x, y); }, 2.0);
  const Eigen::VectorXd rhs = r.stepper->system_rhs();
  Eigen::VectorXd s(rhs.size());
  const double v_cycle = time_ms(
      20, [&] { r.stepper->preconditioner().multigrid().apply(rhs, s); }, 2.0);
  const int n = r.scene.mesh.num_nodes();
  std::ostringstream out;
  out << "| " << r.name << " | " << q.bandwidth << " | " << fixed(q.profile / n, 0) << " | "
      << fixed(q.element_spread, 0) << " | " << r.stepper->elements().colours() << " | "
      << fixed(median(r.element_ms), 2) << " | " << fixed(spmv, 3) << " | " << fixed(v_cycle, 3)
      << " | " << median(r.iterations) << " |\n";
  return out.str();
}

std::string one_mesh_table(const LessonRun& run) {
  std::vector<Run> runs = runs_for(run);
  for (Run& r : runs) {
    NodeOrderStepper::Params params;
    params.order.ordering = r.ordering;
    r.stepper = std::make_unique<NodeOrderStepper>(r.scene, SolverSettings{}, params);
    r.state = rest_state(r.scene);
  }
  // Interleaved, one step of each order in turn, as fem_bench runs chapters: a drift of the
  // machine's speed hits every order alike. The first two steps set up and are not timed.
  for (int k = 0; k < run.steps + 2; ++k) {
    step_progress("node-order", k, run.steps + 2, 5);
    for (Run& r : runs) {
      r.stepper->step(r.state);
      if (k < 2) continue;
      r.element_ms.push_back(1e3 * r.stepper->profile().forces.seconds);
      r.iterations.push_back(r.stepper->profile().cg_iterations);
    }
  }
  std::ostringstream out;
  out << "| " << mesh_name(run.scene) << " (" << run.scene.mesh.num_nodes() << " nodes, "
      << run.scene.mesh.num_tets() << " tets), order | bandwidth | envelope per row | element "
      << "spread | colours | element pass, ms | SpMV, ms | V-cycle, ms | CG it. |\n"
      << "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n";
  for (Run& r : runs) out << row(r);
  out << "\nOne thread; medians of " << run.steps << " steps (the element pass: the `forces` "
      << "phase, which also fills A and b) and of repeated products on the last system. "
      << "Bandwidth: max |i - j| over coupled nodes; envelope: mean of i - min j over rows; "
      << "element spread: mean of the largest minus the smallest node number of an element. "
      << "`original` keeps the file's numbering and element order (chapter 10); `gmsh` rows: "
      << "the file renumbered by gmsh's computeRenumbering "
      << "(tools/femtools/runs/renumber_meshes.py), its elements sorted as chapter 11 sorts them. "
      << measured_on() << ".\n";
  return out.str();
}

// The scene's mesh, then each of --meshes (the same scene and material on it): one table each.
std::string node_order_table(const LessonRun& run) { return on_every_mesh(run, one_mesh_table); }

void add_node_order_options(ArgParser& args) {
  args.option("meshes", "LIST", "further meshes, comma-separated: a table for each", "");
}

}  // namespace

std::vector<Lesson> lessons() {
  Lesson node_order{
      "node-order",
      "the same scene in each node order: bandwidth, element spread, element pass, SpMV, V-cycle",
      "meshes/plate_poster.msh",
      add_node_order_options,
      [](const LessonRun& run) { return node_order_table(run); },
      false};
  // gmsh's own orders beside the chapter's, on the plate, beam_10k and the 82k-node beam.
  node_order.record_args = {"--steps", "10", "--meshes", "meshes/beam_10k.msh"};
  node_order.record_meshes_if_present = {"meshes/generated/beam_100k.msh"};
  return {node_order};
}

}  // namespace fem::ch11
