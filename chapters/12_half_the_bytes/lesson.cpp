// Chapter 12's lesson table: `fem_lessons half-the-bytes` (see lesson.hpp).
#include "chapters/12_half_the_bytes/lesson.hpp"

#include <algorithm>
#include <array>
#include <functional>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>

#include "chapters/11_node_order/node_order.hpp"
#include "chapters/11_node_order/stepper.hpp"
#include "chapters/12_half_the_bytes/stepper.hpp"
#include "common/cli.hpp"
#include "common/mesh.hpp"
#include "common/model.hpp"

namespace fem::ch12 {

namespace {

// The table's rows: chapter 11's V-cycle in double (no Arithmetic: no float numbers), then
// chapter 12's float V-cycle in each arithmetic.
struct Variant {
  const char* name;
  std::optional<Arithmetic> arithmetic;
};
const Variant kVariants[] = {{"double (chapter 11)", std::nullopt},
                             {"float", Arithmetic::single},
                             {"float numbers, double arithmetic", Arithmetic::double_on_float}};

// Chapter 12's recipe with its float numbers widened to double in registers.
struct HalfTheBytesWidened : HalfTheBytes {
  using Preconditioner = ReducedMultigrid<double>;
};

// One variant of the preconditioner: a stepper at the default tolerance (times, iterations)
// and one at each tight tolerance (iterations), stepped side by side.
struct Run {
  Variant variant;
  std::unique_ptr<Stepper> stepper;
  std::vector<std::unique_ptr<Stepper>> tight;
  // One V-cycle of the stepper's preconditioner, outside a team (on this thread), and the
  // bytes of its float numbers (0 for chapter 11's in double).
  std::function<void(const Eigen::VectorXd&, Eigen::VectorXd&)> v_cycle;
  long long float_bytes = 0;
  const Eigen::VectorXd* rhs = nullptr;  // the last step's filtered right-hand side
  State state;
  std::vector<State> tight_state;
  std::vector<double> solve_ms, iterations;
  std::vector<std::vector<double>> tight_iterations;
  bool converged = true;
};

template <class S>
std::unique_ptr<Stepper> made(std::unique_ptr<S> stepper, Run* timed) {
  if (timed) {
    ch08::PreconditionerPart* M = &stepper->preconditioner();
    timed->v_cycle = [M](const Eigen::VectorXd& r, Eigen::VectorXd& s) { M->apply(r, s); };
    timed->rhs = &stepper->system_rhs();
    if constexpr (std::is_same_v<S, HalfBytesStepper>)
      timed->float_bytes = stepper->preconditioner().v_cycle().number_bytes();
  }
  return stepper;
}

// The variant's stepper; `timed` (the default tolerance's run) gets its V-cycle.
std::unique_ptr<Stepper> make(const Scene& scene, const Variant& variant, double tolerance,
                              Run* timed = nullptr) {
  SolverSettings settings;
  settings.tolerance = tolerance;
  if (!variant.arithmetic)
    return made(std::make_unique<ch11::NodeOrderStepper>(scene, settings), timed);
  if (*variant.arithmetic == Arithmetic::single)
    return made(std::make_unique<HalfBytesStepper>(scene, settings), timed);
  return made(std::make_unique<ch08::StepOf<HalfTheBytesWidened>>(scene, settings), timed);
}

double v_cycle_ms(Run& r) {
  const Eigen::VectorXd rhs = *r.rhs;
  Eigen::VectorXd s(rhs.size());
  return time_ms(
      20, [&] { r.v_cycle(rhs, s); }, 2.0);
}

std::string one_mesh_table(const LessonRun& run, const std::vector<double>& tight) {
  std::vector<Run> runs;
  for (const Variant& variant : kVariants) {
    Run& r = runs.emplace_back();
    r.variant = variant;
    r.stepper = make(run.scene, variant, SolverSettings{}.tolerance, &r);
    r.state = rest_state(run.scene);
    for (const double t : tight) {
      r.tight.push_back(make(run.scene, variant, t));
      r.tight_state.push_back(r.state);
    }
    r.tight_iterations.resize(tight.size());
  }
  // Interleaved, one step of each in turn; the first two steps set up and are not timed.
  for (int k = 0; k < run.steps + 2; ++k) {
    step_progress("half-the-bytes", k, run.steps + 2, 5);
    for (Run& r : runs) {
      r.stepper->step(r.state);
      r.converged = r.converged && r.stepper->profile().converged;
      for (std::size_t t = 0; t < tight.size(); ++t) {
        r.tight[t]->step(r.tight_state[t]);
        r.converged = r.converged && r.tight[t]->profile().converged;
        if (k >= 2) r.tight_iterations[t].push_back(r.tight[t]->profile().cg_iterations);
      }
      if (k < 2) continue;
      r.solve_ms.push_back(1e3 * r.stepper->profile().solve.seconds);
      r.iterations.push_back(r.stepper->profile().cg_iterations);
    }
  }
  // Chapter 10's numbers in double take twice the float ones' bytes (the tests check it).
  const long long bytes = 2 * runs[1].float_bytes;  // Arithmetic::single
  const double mb = 1e-6 * static_cast<double>(bytes);
  std::ostringstream out;
  out << "| " << mesh_name(run.scene) << " (" << run.scene.mesh.num_nodes() << " nodes), V-cycle"
      << " | its numbers, MB | one V-cycle, ms | solve, ms | CG it. at "
      << SolverSettings{}.tolerance;
  for (const double t : tight) out << " | CG it. at " << t;
  out << " |\n| --- | ---: | ---: | ---: | ---:";
  for (std::size_t t = 0; t < tight.size(); ++t) out << " | ---:";
  out << " |\n";
  for (Run& r : runs) {
    out << "| " << r.variant.name << " | " << fixed(r.variant.arithmetic ? mb / 2 : mb, 2) << " | "
        << fixed(v_cycle_ms(r), 3) << " | " << fixed(median(r.solve_ms), 2) << " | "
        << median(r.iterations);
    for (const auto& its : r.tight_iterations) out << " | " << median(its);
    out << (r.converged ? "" : " (a solve did not converge)") << " |\n";
  }
  out << "\nOne thread; medians of " << run.steps << " steps, and of repeated V-cycles on the "
      << "last system. Numbers: every level's blocks and inverse diagonals and both "
      << "prolongators (the coarsest level's dense Cholesky factor stays double in both). "
      << measured_on() << ".\n";
  return out.str();
}

std::string half_the_bytes_table(const LessonRun& run) {
  std::vector<double> tight;
  std::stringstream tolerances(run.args.get("tight"));
  for (std::string t; std::getline(tolerances, t, ',');) {
    const std::optional<double> value = parse_double(t);
    if (!value || !(*value > 0.0 && *value < 1.0))
      throw std::invalid_argument("--tight: tolerances in (0, 1), comma-separated, not '" + t +
                                  "'");
    tight.push_back(*value);
  }
  return on_every_mesh(run, [&](const LessonRun& r) { return one_mesh_table(r, tight); });
}

// The four element passes of the table, each with its own elements' state, so that each
// step's rotations start from the last two steps' (and the system they scatter into).
struct ElementPasses {
  ElementPasses(const Model& model, const Scene& scene)
      : model(model),
        one(model, scene),
        one_pass(model, scene),
        batched(model, scene),
        batched_pass(model, scene),
        A(node_adjacency(scene.mesh)),
        index(A, model.tets),
        b(Eigen::VectorXd::Zero(model.dofs)) {}

  // ms of each pass over the whole mesh on this state: the terms one at a time, kLanes at a
  // time, and each with its scatter (braces: evaluated in this order).
  std::array<double, 4> time(const State& state) {
    return {one_ms(one, state, false), batched_ms(batched, state, false),
            one_ms(one_pass, state, true), batched_ms(batched_pass, state, true)};
  }
  double one_ms(ch08::FusedElements& elements, const State& state, bool scatter) {
    long long fallbacks = 0;
    const double ms = time_ms(1, [&] {
      for (int e = 0; e < static_cast<int>(model.tets.size()); ++e) {
        elements.terms(e, model.tets[e], state, fallbacks, terms);
        if (scatter) ch08::scatter(model.tets[e], index.element[e], terms, A, b);
      }
    });
    elements.end_pass(fallbacks);
    return ms;
  }
  double batched_ms(BatchedElements& elements, const State& state, bool scatter) {
    const int n = static_cast<int>(model.tets.size());
    long long fallbacks = 0;
    const double ms = time_ms(1, [&] {
      for (int e = 0; e < n; e += kLanes) {
        const int count = std::min(kLanes, n - e);
        elements.terms(e, count, model.tets, state, fallbacks, batch);
        for (int l = 0; scatter && l < count; ++l)
          ch12::scatter(batch, l, model.tets[e + l], index.element[e + l], A, b);
      }
    });
    elements.end_pass(fallbacks);
    return ms;
  }

  const Model& model;
  ch08::FusedElements one, one_pass;
  BatchedElements batched, batched_pass;
  ch08::ElementTerms terms;
  BatchTerms batch;
  ch07::BlockSparseMatrix A;
  const ch07::BlockIndex index;
  Eigen::VectorXd b;
};

// The element terms of every element, one at a time (chapter 08's FusedElements::terms) and
// kLanes at a time (BatchedElements::terms), alone and with their scatter into A and b (the
// whole element pass, serial): ns per element, 1 thread. On the mesh in the order chapter 12
// steps it (chapter 11's: nodes by reverse Cuthill-McKee, elements sorted along them), and
// on the states of chapter 12 stepping it, so the rotations turn as in a run.
std::string one_mesh_elements(const LessonRun& run) {
  const Scene scene =
      ch11::renumbered(run.scene, ch11::node_order(run.scene.mesh, ch11::Ordering::rcm));
  HalfBytesStepper stepper(scene, SolverSettings{});
  const Model model(scene);
  ElementPasses passes(model, scene);
  const double n = static_cast<double>(model.tets.size());
  State state = rest_state(scene);
  std::vector<double> ns[4];
  for (int k = 0; k < run.steps + 2; ++k) {
    step_progress("batched-elements", k, run.steps + 2, 10);
    stepper.step(state);
    const std::array<double, 4> ms = passes.time(state);
    if (k < 2) continue;
    for (int p = 0; p < 4; ++p) ns[p].push_back(1e6 * ms[p] / n);
  }
  const double one_terms = median(ns[0]), batched_terms = median(ns[1]);
  const double one_all = median(ns[2]), batched_all = median(ns[3]);
  std::ostringstream out;
  out << "| `" << mesh_name(scene) << "` | " << model.tets.size() << " | " << fixed(one_terms, 1)
      << " | " << fixed(batched_terms, 1) << " | x" << fixed(one_terms / batched_terms, 2) << " | "
      << fixed(one_all, 1) << " | " << fixed(batched_all, 1) << " | x"
      << fixed(one_all / batched_all, 2) << " |\n";
  return out.str();
}

std::string batched_elements_table(const LessonRun& run) {
  const std::string lanes = std::to_string(kLanes);
  std::string table =
      "| mesh | elements | terms: one at a time (chapter 08), ns per element | terms: " + lanes +
      " at a time (chapter 12) | speedup | with the scatter: chapter 08 | with the scatter: "
      "chapter 12 | speedup |\n| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n";
  table += on_every_mesh(run, one_mesh_elements, "");
  return table +
         "\nOne thread; the terms of every element (rotation, forces, the ten blocks), alone "
         "and with their scatter into A and b (the element pass, serial); medians over " +
         std::to_string(run.steps) + " passes on the states of a run of chapter 12. " +
         measured_on() + ".\n";
}

void add_element_options(ArgParser& args) {
  args.option("meshes", "LIST", "further meshes, comma-separated: a row for each", "");
}

void add_options(ArgParser& args) {
  args.option("meshes", "LIST", "further meshes, comma-separated: a table for each", "");
  args.option("tight", "LIST", "the tight tolerances of the last columns, comma-separated",
              "1e-8,1e-12");
}

}  // namespace

std::vector<Lesson> lessons() {
  std::vector<Lesson> all = {
      {"half-the-bytes",
       "the V-cycle in double, in float, and float numbers in double arithmetic: bytes, time, "
       "iterations",
       "meshes/plate_poster.msh", add_options,
       [](const LessonRun& run) { return half_the_bytes_table(run); }, false},
      {"batched-elements",
       "the element terms one at a time (chapter 08) and a batch per vector register (chapter 12)",
       "meshes/plate_poster.msh", add_element_options,
       [](const LessonRun& run) { return batched_elements_table(run); }, false}};
  all[0].record_args = {"--steps", "10", "--meshes", "meshes/beam_10k.msh"};
  all[1].record_args = {"--steps", "20", "--meshes", "meshes/beam_10k.msh"};
  for (Lesson& l : all) l.record_meshes_if_present = {"meshes/generated/beam_100k.msh"};
  return all;
}

}  // namespace fem::ch12
