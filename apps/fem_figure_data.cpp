// fem_figure_data: the code's own data behind the figures a table cannot show, as JSON for
// fem-tools plots figures (docs/data/figures/): chapter 10's hierarchy (level sizes and the
// aggregate of every node) and chapter 11's node orders. The figures read the mesh file
// themselves; the tet checksum lets them check that they number its nodes as load_mesh does.
#include <iostream>
#include <string>
#include <vector>

#include "chapters/10_multigrid/report.hpp"
#include "chapters/10_multigrid/stepper.hpp"
#include "chapters/11_node_order/node_order.hpp"
#include "common/atomic_file.hpp"
#include "common/cli.hpp"
#include "common/json.hpp"

namespace {

using namespace fem;

std::string ints(const std::vector<int>& v) {
  std::string out = "[";
  for (std::size_t i = 0; i < v.size(); ++i) out += (i ? "," : "") + std::to_string(v[i]);
  return out + "]";
}

// The mesh as the figure scripts check it: sum over tets e of e times its corners' sum.
std::string mesh_record(const ArgParser& args, const Scene& scene) {
  long long checksum = 0;
  for (int e = 0; e < scene.mesh.num_tets(); ++e) checksum += 1LL * e * scene.mesh.tets[e].sum();
  return "  \"schema_version\": 1,\n  \"mesh\": " + json_string(args.get("mesh")) +
         ",\n  \"scene\": " + json_string(scene.name) +
         ",\n  \"nodes\": " + std::to_string(scene.mesh.num_nodes()) +
         ",\n  \"tets\": " + std::to_string(scene.mesh.num_tets()) +
         ",\n  \"tet_checksum\": " + std::to_string(checksum) + ",\n";
}

// Per node of a level with a level below: its aggregate, read from the level's own data (the
// column of its tentative block in P; the aggregation's set-up data is gone after set-up).
template <int B>
std::vector<int> aggregates(const ch10::Level<B>& level) {
  const ch10::Transfer<B>& transfer = level.transfer;
  std::vector<int> out(transfer.tentative_block.size());
  for (std::size_t i = 0; i < out.size(); ++i)
    out[i] = transfer.P.column[transfer.tentative_block[i]];
  return out;
}

// Chapter 10: the hierarchy as the stepper sets it up (set-up only, no step), per level its
// size and the smoothing steps of its V-cycle, per node of a non-coarsest level its aggregate.
void hierarchy(std::ostream& out, const Scene& scene) {
  const ch10::MultigridStepper stepper(scene, SolverSettings{});
  const ch10::Multigrid& mg = stepper.preconditioner().multigrid();
  const ch10::SmootherSettings& relax = mg.settings().relax;
  const bool chebyshev = relax.smoother == ch10::Smoother::Chebyshev;
  out << "  \"smoother\": \"" << (chebyshev ? "Chebyshev" : "other") << "\",\n"
      << "  \"smoothing_steps\": " << (chebyshev ? relax.chebyshev_degree : relax.sweeps)
      << ",\n  \"levels\": [\n";
  for (int l = 0; l < mg.levels(); ++l)
    out << "    {\"block\": " << (l == 0 ? 3 : ch10::kModes)
        << ", \"dofs\": " << ch10::level_dofs(mg, l)
        << ", \"blocks\": " << ch10::level_blocks(mg, l)
        << ", \"parts\": " << ch10::level_row_blocks(mg, l) << "}"
        << (l + 1 < mg.levels() ? ",\n" : "\n");
  out << "  ],\n  \"aggregate\": [\n    " << ints(aggregates(mg.fine_level()));
  for (int l = 1; l + 1 < mg.levels(); ++l)
    out << ",\n    " << ints(aggregates(mg.coarse_levels()[l - 1]));
  out << "\n  ]\n";
}

// Chapter 11: new_of_old of each of its orders, and the bandwidth and envelope they give.
void node_orders(std::ostream& out, const Scene& scene) {
  out << "  \"orders\": {\n";
  const ch11::Ordering orders[] = {ch11::Ordering::rcm, ch11::Ordering::morton};
  for (const ch11::Ordering o : orders) {
    const ch11::NodeOrder order = ch11::node_order(scene.mesh, o);
    const ch11::OrderQuality q = ch11::order_quality(ch11::renumbered(scene, order, false).mesh);
    out << "    \"" << ch11::ordering_name(o) << "\": {\"bandwidth\": " << q.bandwidth
        << ", \"profile\": " << static_cast<long long>(q.profile)
        << ", \"new_of_old\": " << ints(order.new_of_old) << "}" << (o == orders[1] ? "\n" : ",\n");
  }
  const ch11::OrderQuality q = ch11::order_quality(scene.mesh);
  out << "  },\n  \"original\": {\"bandwidth\": " << q.bandwidth
      << ", \"profile\": " << static_cast<long long>(q.profile) << "}\n";
}

}  // namespace

int main(int argc, char** argv) {
  using namespace fem;
  return run_program("fem_figure_data", [&] {
    const std::string what = argc > 1 ? argv[1] : "";
    if (what != "hierarchy" && what != "node-orders")
      throw UsageError(
          "usage: fem_figure_data hierarchy|node-orders --json FILE [--mesh FILE] [--help]");
    ArgParser args("fem_figure_data " + what, "Writes the data of a figure as JSON.");
    add_scene_options(args,
                      what == "hierarchy" ? "meshes/plate_poster.msh" : "meshes/beam_10k.msh");
    args.option("json", "FILE", "where to write the JSON", "");
    if (!args.parse(argc - 1, argv + 1)) return 0;
    if (args.get("json").empty()) throw UsageError("--json FILE is required");
    apply_thread_environment();
    const Scene scene = scene_from_args(args);
    write_file_atomically(args.get("json"), [&](std::ostream& out) {
      out << "{\n" << mesh_record(args, scene) << "  \"figure\": " << json_string(what) << ",\n";
      if (what == "hierarchy")
        hierarchy(out, scene);
      else
        node_orders(out, scene);
      out << "}\n";
    });
    return 0;
  });
}
