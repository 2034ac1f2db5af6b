// The solve's kernels alone (apps/roofline/kernels_alone.hpp): their work, times their calls,
// is the counted work of the solve's parts they stand for (each chapter's own count, through
// the registry's hook), and they run and time on the test mesh. No time is asserted beyond
// being a time (positive and finite).
#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "apps/roofline/kernels_alone.hpp"
#include "catch2_compat.hpp"
#include "chapters/09_threads/stepper.hpp"
#include "chapters/10_multigrid/stepper.hpp"
#include "chapters/course.hpp"
#include "chapters/registry.hpp"
#include "common/build_info.hpp"
#include "support.hpp"

using namespace fem;
using namespace fem::roofline;

namespace {

// A fresh stepper of `id` after two steps, its kernels alone, and its solve as counted.
struct Stepped {
  std::unique_ptr<Stepper> stepper;
  double iterations = 0.0;
  std::vector<KernelAlone> kernels;
  PhaseWork solve;
};

Stepped stepped(const std::string& id, const Scene& scene) {
  const ChapterInfo& chapter = find_chapter(id);
  Stepped s;
  s.stepper = chapter.make(scene, {});
  State state = rest_state(scene);
  for (int k = 0; k < 2; ++k) s.stepper->step(state);
  s.iterations = s.stepper->profile().cg_iterations;
  s.kernels = solve_kernels(chapter, *s.stepper, scene, s.iterations);
  REQUIRE(course_of(chapter).work.count);
  for (const PhaseWork& w :
       course_of(chapter).work.count(*s.stepper, scene, WorkCounts{s.iterations, {}}))
    if (w.phase == "solve") s.solve = w;
  REQUIRE(!s.solve.parts.empty());
  return s;
}

// Under made-up roofs: one level of 10 GB/s read, write, zeroing and written back (an update
// of 20 GB/s read and written), 100 Gflop/s.
Roofs made_up_roofs() {
  Roofs roofs;
  LevelRoof memory;
  memory.level = {"memory", 0, 1 << 20};
  memory.read = memory.write = memory.zero = 1e10;
  memory.update = 1e10;
  roofs.levels = {memory};
  roofs.peak_double = roofs.peak_float = 1e11;
  return roofs;
}

}  // namespace

// Every part the solve's count names has kernels alone that add up to it (the V-cycle's levels,
// their transfers, the coarsest solve, its entry and exit in float, the per-solve prepare: the
// fine blocks into float, the pairs' fill), so that "between the kernels" is what lies between.
TEST_CASE("roofline: the kernels alone make up the solve's counted parts", "[roofline]") {
  const Scene scene = test::test_scene("cantilever");
  const std::map<std::string, std::set<std::string>> expected = {
      {"09", {"pcg", "preconditioner", "prepare"}},
      {"12",
       {"pcg", "preconditioner", "level 0 smoothing and residual", "level 0 restriction",
        "level 0 prolongation", "level 1 coarsest solve", "prepare"}}};
  for (const std::string id : {"09", "12", "13", "14"}) {
    INFO("chapter " << id);
    const Stepped s = stepped(id, scene);
    REQUIRE(s.iterations > 0);
    std::set<std::string> covered, counted_parts;
    for (const KernelAlone& k : s.kernels) covered.insert(k.part);
    for (const PhaseWork& p : s.solve.parts) counted_parts.insert(p.phase);
    std::set<std::string> not_alone;
    for (const std::string& name : counted_parts)
      if (covered.count(name) == 0) not_alone.insert(name);
    CHECK(not_alone.empty());
    CHECK(covered == expected.at(id == "09" ? "09" : "12"));
    for (const std::string& name : covered) {
      INFO("part " << name);
      PhaseWork alone, counted;
      for (const KernelAlone& k : s.kernels)
        if (k.part == name) alone.add_part(k.work, k.calls);
      for (const PhaseWork& p : s.solve.parts)
        if (p.phase == name) counted.add_part(p, 1.0);
      REQUIRE(counted.bytes() > 0);
      CHECK(alone.bytes_read == Approx(counted.bytes_read));
      CHECK(alone.bytes_written == Approx(counted.bytes_written));
      CHECK(alone.bytes_allocated == Approx(counted.bytes_allocated));
      CHECK(alone.flops_double + alone.flops_float ==
            Approx(counted.flops_double + counted.flops_float));
    }
  }
}

TEST_CASE("roofline: the product alone reads the matrix and p and writes q", "[roofline]") {
  const Scene scene = test::test_scene("cantilever");
  const Stepped s = stepped("09", scene);
  const ch09::ThreadsStepper same_pattern(scene, {});
  const auto& A = same_pattern.system_matrix();
  const double v = 3.0 * scene.mesh.num_nodes() * 8;
  const double matrix = A.blocks.size() * 72.0 + (A.column.size() + A.row_start.size()) * 4.0;
  // The product's loop also sums its rows of p . q as it writes them (pcg_product).
  REQUIRE(s.kernels.front().name == "product q = A p and p . q");
  CHECK(s.kernels.front().work.bytes_read == Approx(matrix + v));
  CHECK(s.kernels.front().work.bytes_written == Approx(v));
  CHECK(s.kernels.front().work.flops_double ==
        Approx(18.0 * A.blocks.size() + 2.0 * 3.0 * scene.mesh.num_nodes()));
  CHECK(s.kernels.front().calls == Approx(s.iterations + 1));
}

TEST_CASE("roofline: the kernels alone run and are timed", "[roofline]") {
  const Scene scene = test::test_scene("cantilever");
  for (const std::string id : {"09", "12"}) {
    INFO("chapter " << id);
    const Stepped s = stepped(id, scene);
    for (int threads = 1; threads <= std::min(2, int(hardware_threads())); ++threads)
      for (const KernelAlone& k : s.kernels) {
        INFO(k.name << " at " << threads << " thread(s)");
        const double t = best_call_seconds(threads, k.run);
        CHECK(std::isfinite(t));
        CHECK(t > 0.0);
      }
  }
}

TEST_CASE("roofline: a placed solve beside its kernels alone", "[roofline]") {
  const Scene scene = test::test_scene("cantilever");
  const ChapterInfo& chapter = find_chapter("12");
  const Roofs roofs = made_up_roofs();
  const Stepped s = stepped("12", scene);
  PlacedRun run;
  run.chapter = chapter.id;
  run.mesh = mesh_name(scene);
  run.iterations = s.iterations;
  PhasePoint solve;
  solve.work = s.solve;
  solve.bound_s = bound_seconds(roofs, s.solve);
  solve.measured_s = 1.0;
  run.phases = {solve};
  const std::vector<AloneRun> alone = kernels_alone({&chapter}, scene, {roofs}, {run});
  REQUIRE(alone.size() == 1);
  const AloneRun& a = alone.front();
  // Chapter 09's three PCG loops; the fine smoothing step, the fine level's two transfers, the
  // coarsest solve (the test beam's hierarchy has two levels), the entry and exit in float; the
  // prepare.
  CHECK(a.kernels.size() == s.kernels.size());
  CHECK(a.kernels.size() == 9);
  // The solve timed in turn with them, and the kernels' calls counted at its iterations.
  CHECK(a.solve_rounds == 15);
  CHECK(std::isfinite(a.solve_s));
  CHECK(a.solve_s > 0.0);
  REQUIRE(a.solve_iterations > 0);
  CHECK(a.kernels.front().calls == Approx(a.solve_iterations + 1));
  CHECK(a.kernels.back().calls == 1.0);
  CHECK(std::isfinite(a.alone_s));
  CHECK(a.alone_s > 0.0);
  // The solve's bound at the timed solve's iterations (the placement's waiting: none here).
  for (const PhaseWork& w :
       course_of(chapter).work.count(*s.stepper, scene, WorkCounts{a.solve_iterations, {}}))
    if (w.phase == "solve") CHECK(a.solve_bound_s == Approx(bound_seconds(roofs, w)));
  CHECK(a.parts_bound_s > 0.0);
  CHECK(a.parts_bound_s == Approx(a.solve_bound_s));  // every counted part has its kernels
  for (const KernelAlone& k : a.kernels) CHECK(k.bound_s == Approx(bound_seconds(roofs, k.work)));
  const std::string table = kernels_alone_table(alone);
  CHECK(table.find("fine smoothing step") != std::string::npos);
  CHECK(with_kernels_alone("{}", alone).find("\"kernels_alone\"") != std::string::npos);
}
