// The work counts (each chapter's work.hpp, through the registry's hook) against the data
// structures they count, computed here independently from the stepper's objects; the flops
// of the element pass against the iterations the kernel counted; the working sets of the
// roofs; and each phase's waiting against its own synchronizations. No timing is asserted:
// the roofs' second measurement is reported by the lesson (fem_lessons roofline), not tested.
#include <cstdlib>

#include "apps/roofline/bandwidth.hpp"
#include "apps/roofline/likwid.hpp"
#include "apps/roofline/placement.hpp"
#include "catch2_compat.hpp"
#include "chapters/01_naive/work.hpp"
#include "chapters/07_block_sparse/stepper.hpp"
#include "chapters/07_block_sparse/work.hpp"
#include "chapters/08_element_kernels/stepper.hpp"
#include "chapters/08_element_kernels/work.hpp"
#include "chapters/09_threads/stepper.hpp"
#include "chapters/10_multigrid/report.hpp"
#include "chapters/10_multigrid/stepper.hpp"
#include "chapters/10_multigrid/work.hpp"
#include "chapters/11_node_order/stepper.hpp"
#include "chapters/12_half_the_bytes/stepper.hpp"
#include "chapters/12_half_the_bytes/work.hpp"
#include "chapters/course.hpp"
#include "chapters/registry.hpp"
#include "common/threads.hpp"
#include "support.hpp"

using namespace fem;

namespace {

const PhaseWork& phase(const std::vector<PhaseWork>& work, const std::string& name) {
  for (const auto& w : work)
    if (w.phase == name) return w;
  FAIL("no phase " << name);
  return work.front();
}

// `steps` steps of `stepper` from rest, and its work counted by its chapter's hook with the
// counters of those steps.
std::vector<PhaseWork> stepped_work(const ChapterInfo& chapter, Stepper& stepper,
                                    const Scene& scene, int steps) {
  State state = rest_state(scene);
  for (int k = 0; k < steps; ++k) stepper.step(state);
  REQUIRE(course_of(chapter).work.count);
  WorkCounts counts{double(stepper.profile().cg_iterations), {}};
  if (course_of(chapter).work.executed) {
    counts.per_step = course_of(chapter).work.executed(stepper);
    const double n = counts.per_step.steps;
    counts.per_step = {1.0, counts.per_step.rotations / n, counts.per_step.rotation_iterations / n,
                       counts.per_step.rotation_fallbacks / n};
  }
  return course_of(chapter).work.count(stepper, scene, counts);
}

}  // namespace

TEST_CASE("roofline: chapter 07's matrix bytes are its blocks and indices", "[roofline]") {
  const Scene scene = test::test_scene("cantilever");
  const ChapterInfo& chapter = find_chapter("07");
  ch07::BlockSparseStepper stepper(scene, {});
  const auto work = stepped_work(chapter, stepper, scene, 1);
  const auto& A = stepper.system_matrix();
  const double expected =
      double(A.blocks.size()) * 72.0 + double(A.column.size() + A.row_start.size()) * 4.0;
  CHECK(ch07::matrix_bytes(A) == expected);
  // The solve: per product the matrix and the block-Jacobi inverses read; 8 vectors read, 5
  // written, 2 of them (q and z) to lines not read first.
  const double it = stepper.profile().cg_iterations;
  const double v = 3.0 * scene.mesh.num_nodes() * 8;
  const double read = expected + scene.mesh.num_nodes() * 72.0 + 8 * v;
  CHECK(phase(work, "solve").bytes_read == Approx((it + 1) * read));
  CHECK(phase(work, "solve").bytes_written == Approx((it + 1) * 5 * v));
  CHECK(phase(work, "solve").bytes_allocated == Approx((it + 1) * 2 * v));
  // The constraints: the blocks of constrained rows and columns, read and written back.
  double blocks = 0;
  for (const NodeConstraint& c : scene.constraints)
    blocks += A.row_start[c.node + 1] - A.row_start[c.node];
  REQUIRE(blocks > 0);
  CHECK(phase(work, "constraints").bytes_read == Approx(2 * 72 * blocks + v));
  CHECK(phase(work, "constraints").bytes_written == Approx(2 * 72 * blocks + v));
}

TEST_CASE("roofline: chapter 01's matrix bytes are Eigen's compressed storage", "[roofline]") {
  const Scene scene = test::test_scene("cantilever");
  ch01::NaiveStepper stepper(scene, {});
  State state = rest_state(scene);
  stepper.step(state);
  const Eigen::SparseMatrix<double>& dfdx = stepper.dfdx();
  REQUIRE(dfdx.isCompressed());
  const double expected = double(dfdx.nonZeros()) * (8 + 4) + double(dfdx.cols() + 1) * 4;
  CHECK(ch01::matrix_bytes(dfdx) == expected);
  // df/dx is written fresh, once per step: its bytes written are the matrix's.
  const auto work = ch01::count_work(stepper, scene, {1.0, {}});
  CHECK(phase(work, "dfdx").bytes_written == expected);
  CHECK(phase(work, "dfdx").bytes_allocated == expected);
  // Every entry of df/dx is one of 3x3 blocks of the chapter 07 pattern on the same mesh.
  ch07::BlockSparseStepper blocks(scene, {});
  blocks.step(state);
  CHECK(double(dfdx.nonZeros()) == 9.0 * double(blocks.system_matrix().blocks.size()));
}

TEST_CASE("roofline: the fused pass's writes are the objects it writes", "[roofline]") {
  const Scene scene = test::test_scene("cantilever");
  const ChapterInfo& chapter = find_chapter("08");
  ch08::ElementKernelsStepper s(scene, {});
  const auto work = stepped_work(chapter, s, scene, 2);
  // Both rotations of every element, every block of A and b: their sizes in memory.
  const double rotations =
      double(s.elements().fused().rotations().size()) * sizeof(Eigen::Quaterniond) +
      double(s.elements().fused().previous_rotations().size()) * sizeof(Eigen::Quaterniond);
  const double A = double(s.system_matrix().blocks.size()) * sizeof(Eigen::Matrix3d);
  const double b = double(s.system_rhs().size()) * sizeof(double);
  CHECK(phase(work, "forces").bytes_written == Approx(rotations + A + b));
  CHECK(phase(work, "forces").bytes_allocated == 0.0);  // each line read before it is written
  // compose zeroes A (at the zeroing roof) and writes b afresh.
  CHECK(phase(work, "compose").bytes_written == Approx(A + b));
  CHECK(phase(work, "compose").bytes_allocated == Approx(b));
  CHECK(phase(work, "compose").bytes_zeroed == Approx(A));
}

TEST_CASE("roofline: the element pass's flops are the Newton iterations it counted", "[roofline]") {
  const Scene scene = test::test_scene("cantilever");
  for (const char* id : {"08", "12"}) {
    const ChapterInfo& chapter = find_chapter(id);
    const auto stepper = chapter.make(scene, {});
    State state = rest_state(scene);
    for (int k = 0; k < 3; ++k) stepper->step(state);
    REQUIRE(course_of(chapter).work.executed);
    const ExecutedWork e = course_of(chapter).work.executed(*stepper);
    const double elements = scene.mesh.num_tets();
    CHECK(e.steps == 3.0);
    CHECK(e.rotations == 3.0 * elements);
    // Newton from the predicted rotation: at least one iteration per rotation it decided.
    CHECK(e.rotation_iterations >= e.rotations - e.rotation_fallbacks);
    CHECK(e.rotation_iterations <= e.rotations * ch08::newton::kMaxIterations);
    const WorkCounts counts{
        1.0, {1.0, e.rotations / 3, e.rotation_iterations / 3, e.rotation_fallbacks / 3}};
    const auto work = course_of(chapter).work.count(*stepper, scene, counts);
    const double expected = elements * ch08::fused_element_flops() +
                            e.rotation_iterations / 3 * ch08::newton_iteration_flops() +
                            e.rotations / 3 * ch08::newton_finish_flops();
    CHECK(phase(work, "forces").flops_double == Approx(expected));
  }
}

TEST_CASE("roofline: a chapter is counted from its own data, not its base's", "[roofline]") {
  // Chapter 12 derives from 11 and keeps the V-cycle's levels in float: its own count (its
  // work.hpp, found for its class) moves fewer bytes in the solve than 11's, whose count is
  // chapter 10's (11 adds no data), on the same hierarchy.
  const Scene scene = test::test_scene("cantilever");
  const ChapterInfo& c11 = find_chapter("11");
  const ChapterInfo& c12 = find_chapter("12");
  auto s11 = std::make_unique<ch11::NodeOrderStepper>(scene, SolverSettings{});
  auto s12 = std::make_unique<ch12::HalfBytesStepper>(scene, SolverSettings{});
  const auto w11 = stepped_work(c11, *s11, scene, 1);
  const auto w12 = stepped_work(c12, *s12, scene, 1);
  const auto& m11 = s11->preconditioner().multigrid();
  const auto& m12 = s12->preconditioner().multigrid();
  const auto v11 =
      ch10::v_cycle_work(ch10::multigrid_levels(m11), ch10::smoother_products(m11), 8, false);
  const auto v12 =
      ch10::v_cycle_work(ch10::multigrid_levels(m12), ch10::smoother_products(m12), 4, true);
  CHECK(v12.bytes() < v11.bytes());
  // Per iteration of the solve, the V-cycle's bytes are the chapter's own.
  const double it11 = s11->profile().cg_iterations, it12 = s12->profile().cg_iterations;
  CHECK(phase(w12, "solve").bytes() / (it12 + 1) < phase(w11, "solve").bytes() / (it11 + 1));
  CHECK(phase(w12, "solve").flops_float > 0.0);
  CHECK(phase(w11, "solve").flops_float == 0.0);
}

TEST_CASE("roofline: the V-cycle's levels are the hierarchy's matrices", "[roofline]") {
  const Scene scene = test::test_scene("cantilever");
  ch10::MultigridStepper stepper(scene, {});
  State state = rest_state(scene);
  stepper.step(state);
  const auto levels = ch10::multigrid_levels(stepper.preconditioner().multigrid());
  REQUIRE(int(levels.size()) == stepper.preconditioner().multigrid().levels());
  CHECK(levels.back().coarsest);
  for (std::size_t l = 0; l < levels.size(); ++l) {
    const auto A = ch10::level_matrix(stepper.preconditioner().multigrid(),
                                      int(l));  // an independent conversion
    const int b = levels[l].block;
    CHECK(double(levels[l].nodes * b) == double(A.rows()));
    CHECK(double(levels[l].blocks) * b * b >= double(A.nonZeros()));  // zero entries not stored
    if (!levels[l].coarsest)
      CHECK(double(levels[l].transfer) * b * ch10::kModes >=
            double(ch10::prolongator(stepper.preconditioner().multigrid(), int(l)).nonZeros()));
  }
  // A float V-cycle streams fewer bytes than a double one over the same levels.
  const int products = ch10::smoother_products(stepper.preconditioner().multigrid());
  CHECK(products >= 2);
  CHECK(ch10::v_cycle_work(levels, products, 4, true).bytes() <
        ch10::v_cycle_work(levels, products, 8, false).bytes());
}

namespace {

// The bytes of one level's matrix (its blocks in `scalar` bytes each, its indices), its
// inverse diagonal and one vector, and of its prolongator P, from the level's own objects.
template <int B>
struct LevelBytes {
  double matrix, inverse, vector, transfer;
  LevelBytes(const ch10::Level<B>& l, int scalar) {
    const double b2 = double(B) * B;
    matrix = double(l.A.column.size()) * b2 * scalar +
             double(l.A.column.size() + l.A.row_start.size()) * sizeof(int);
    inverse = double(l.smoother.inverse_diagonal.size()) * b2 * scalar;
    vector = double(l.vectors.x.size()) * scalar;
    const auto& P = l.transfer.P;
    transfer = l.coarsest ? 0.0
                          : double(P.column.size()) * B * ch10::kModes * scalar +
                                double(P.column.size() + P.row_start.size()) * sizeof(int);
  }
};

// The V-cycle's parts of level `k`, checked against its objects: the smoothing and residual
// products each read the matrix, the inverse diagonal and three vectors, restriction and
// prolongation each the operator and one vector; each part's working set its level's data.
template <int B>
void check_level(const PhaseWork& v, const ch10::Level<B>& l, int k, int products, int scalar) {
  INFO("level " << k);
  const LevelBytes<B> b(l, scalar);
  const std::string name = "level " + std::to_string(k) + " ";
  const PhaseWork& smoothing = phase(v.parts, name + "smoothing and residual");
  CHECK(smoothing.bytes_read == Approx(products * (b.matrix + b.inverse + 3 * b.vector)));
  CHECK(smoothing.bytes_written == Approx(products * 2 * b.vector));
  CHECK(smoothing.working_set == Approx(b.matrix + b.inverse + 4 * b.vector));
  const PhaseWork& restriction = phase(v.parts, name + "restriction");
  const PhaseWork& prolongation = phase(v.parts, name + "prolongation");
  CHECK(restriction.bytes_read == Approx(b.transfer + b.vector));
  CHECK(prolongation.bytes_read == Approx(b.transfer + b.vector));
  CHECK(prolongation.bytes_written == Approx(b.vector));
  CHECK(restriction.working_set == Approx(b.transfer + b.vector));
}

}  // namespace

TEST_CASE("roofline: the V-cycle is counted per level, each part on its own data", "[roofline]") {
  const Scene scene = test::test_scene("cantilever");
  ch10::MultigridStepper stepper(scene, {});
  State state = rest_state(scene);
  stepper.step(state);
  const ch10::Multigrid& mg = stepper.preconditioner().multigrid();
  REQUIRE(mg.levels() >= 2);
  const int products = ch10::smoother_products(mg);
  for (const int scalar : {8, 4}) {
    INFO("scalar " << scalar);
    const PhaseWork v = ch10::v_cycle_work(ch10::multigrid_levels(mg), products, scalar, false);
    check_level(v, mg.fine_level(), 0, products, scalar);
    for (int k = 1; k + 1 < mg.levels(); ++k)
      check_level(v, mg.coarse_levels()[k - 1], k, products, scalar);
    // The coarsest level: its dense Cholesky factor, in double whatever the levels' scalar.
    const auto& coarsest = mg.coarse_levels().back();
    const PhaseWork& solve =
        phase(v.parts, "level " + std::to_string(mg.levels() - 1) + " coarsest solve");
    CHECK(solve.bytes_read == double(coarsest.coarsest_solve.dense.size()) * sizeof(double));
    // The parts are the whole: nothing counted outside them.
    double read = 0.0, written = 0.0;
    for (const PhaseWork& p : v.parts) {
      CHECK(p.parts.empty());
      CHECK(p.working_set <= v.working_set);
      read += p.bytes_read;
      written += p.bytes_written;
    }
    CHECK(read == Approx(v.bytes_read));
    CHECK(written == Approx(v.bytes_written));
    CHECK(v.parts.size() == std::size_t(3 * (mg.levels() - 1) + 1));
  }
  // In the chapter's solve, every V-cycle part runs once per PCG pass, beside the PCG's own.
  const ChapterInfo& c10 = find_chapter("10");
  auto s10 = std::make_unique<ch10::MultigridStepper>(scene, SolverSettings{});
  const auto work = stepped_work(c10, *s10, scene, 1);
  const PhaseWork& solve = phase(work, "solve");
  const double passes = s10->profile().cg_iterations + 1.0;
  const auto& m10 = s10->preconditioner().multigrid();
  const PhaseWork v = ch10::v_cycle_work(ch10::multigrid_levels(m10), products, 8, false);
  const PhaseWork& fine = phase(solve.parts, "level 0 smoothing and residual");
  CHECK(fine.bytes_read == Approx(passes * phase(v.parts, fine.phase).bytes_read));
  CHECK(phase(solve.parts, "pcg").working_set < solve.working_set);
  double read = 0.0;
  for (const PhaseWork& p : solve.parts) read += p.bytes_read;
  CHECK(read == Approx(solve.bytes_read));
}

TEST_CASE("roofline: every chapter of the course counts its work through the registry",
          "[roofline]") {
  const Scene scene = test::test_scene("cantilever");
  for (const ChapterInfo& c : chapters()) {
    if (!c.variant_of.empty()) continue;
    INFO(c.id);
    const auto stepper = c.make(scene, {});
    const auto work = stepped_work(c, *stepper, scene, 1);
    CHECK(work.size() >= 4);
    for (const auto& w : work) {
      CHECK(w.bytes_read > 0);
      CHECK(w.bytes_allocated + w.bytes_zeroed <= w.bytes_written);
      CHECK(w.working_set <= w.bytes());
    }
  }
}

TEST_CASE("roofline: the roofs' working sets fit the levels they measure", "[roofline]") {
  const std::vector<CacheLevel> caches = {
      {1, "Data", 48 << 10, 1}, {2, "Unified", 1 << 20, 1}, {3, "Unified", 32 << 20, 2}};
  for (const int threads : {1, 2}) {
    const auto levels = roofline::memory_levels(caches, threads);
    REQUIRE(levels.size() == 4);
    for (std::size_t l = 0; l + 1 < levels.size(); ++l)
      CHECK(levels[l].working_set * 2 <= levels[l].capacity);
    // The shared L3 is split between the threads; memory is four times the largest cache.
    CHECK(levels[2].capacity == std::size_t(32 << 20) / threads);
    CHECK(levels.back().working_set * threads >= std::size_t(4) * (32 << 20));
    // The private levels measured on half of themselves but at most eight times the level
    // inside; the shared one on at most four times the level inside it.
    CHECK(levels[0].working_set == std::size_t(24 << 10));
    CHECK(levels[1].working_set == std::size_t(384 << 10));
    CHECK(levels[2].working_set == std::size_t(4 << 20));
  }
  // A virtual machine that reports a 480 MiB L3 beside 2 MiB of L2: measured on 8 MiB a thread.
  const std::vector<CacheLevel> vm = {
      {1, "Data", 48 << 10, 1}, {2, "Unified", 2 << 20, 1}, {3, "Unified", 480 << 20, 2}};
  CHECK(roofline::memory_levels(vm, 2)[2].working_set == std::size_t(8 << 20));
  // ... which holds no more than that; its private L2 all of itself.
  CHECK(roofline::memory_levels(vm, 2)[2].holds() == std::size_t(8 << 20));
  CHECK(roofline::memory_levels(vm, 2)[1].holds() == std::size_t(2 << 20));
}

namespace {

// Roofs made by hand: one level (memory) and the costs of one barrier and one region, so that
// what the placement prices is known exactly.
roofline::Roofs hand_roofs(int threads) {
  roofline::Roofs roofs;
  roofs.threads = threads;
  roofline::LevelRoof memory;
  memory.level = {"memory", 0, 1 << 20};
  memory.read = 10e9;
  memory.write = 5e9;
  memory.update = 8e9;
  memory.zero = 20e9;
  roofs.levels = {memory};
  roofs.peak_double = 20e9;
  roofs.peak_float = 40e9;
  roofs.barrier_s = threads > 1 ? 1e-6 : 0.0;
  roofs.region_s = threads > 1 ? 4e-6 : 0.0;
  return roofs;
}

}  // namespace

TEST_CASE("roofline: each phase's waiting is its own synchronizations at their costs",
          "[roofline]") {
  // The adaptive team off (chapter 09 reads FEM_ADAPTIVE_TEAM when a stepper is made): every
  // measured step on the team of two, so every count is priced at the two-thread costs.
  const char* adaptive = std::getenv("FEM_ADAPTIVE_TEAM");
  const std::string saved = adaptive ? adaptive : "";
  setenv("FEM_ADAPTIVE_TEAM", "0", 1);
  const Scene scene = test::test_scene("cantilever");
  const int threads = openmp_enabled() ? 2 : 1;
  const roofline::Roofs roofs = hand_roofs(threads);
  const auto runs = roofline::place_chapter(find_chapter("13"), scene, {roofs}, 1, 3);
  adaptive ? setenv("FEM_ADAPTIVE_TEAM", saved.c_str(), 1) : unsetenv("FEM_ADAPTIVE_TEAM");
  REQUIRE(runs.size() == 1);
  const roofline::PlacedRun& run = runs.front();
  CHECK(run.team_min == threads);
  CHECK(run.team_max == threads);
  REQUIRE(run.phases.size() >= 4);
  double regions = 0.0, barriers = 0.0, waiting = 0.0;
  for (const roofline::PhasePoint& p : run.phases) {
    INFO(p.work.phase);
    CHECK(p.waiting_s == Approx(p.regions * roofs.region_s + p.barriers * roofs.barrier_s));
    CHECK(p.bound_s == Approx(std::max(p.memory_s, p.arithmetic_s) + p.waiting_s));
    const std::string held = roofline::held_by(p.memory_s, p.arithmetic_s, p.waiting_s);
    CHECK(held == (p.waiting_s > std::max(p.memory_s, p.arithmetic_s) ? "waiting"
                   : p.memory_s >= p.arithmetic_s                     ? "bytes"
                                                                      : "flops"));
    regions += p.regions;
    barriers += p.barriers;
    waiting += p.waiting_s;
  }
  // The phases cover the step but for the update: their counts are the step's.
  CHECK(regions == Approx(run.regions));
  CHECK(barriers == Approx(run.barriers));
  CHECK(waiting == Approx(run.waiting_s));
  const roofline::PhasePoint& solve = run.phases.back();
  REQUIRE(solve.work.phase == "solve");
  CHECK(solve.barriers >= run.iterations);  // a barrier or more per PCG iteration
  if (threads > 1) CHECK(solve.waiting_s > 0.0);
}

TEST_CASE(
    "roofline: each written byte at the roof of its kind, each working set where its "
    "roof was measured",
    "[roofline]") {
  // A shared cache that reports 1 MiB and was measured on 256 KiB, and memory.
  roofline::Roofs roofs = hand_roofs(1);
  roofline::LevelRoof cache;
  cache.level = {"L3", 1 << 20, 256 << 10, true};
  cache.read = 100e9;
  cache.write = 50e9;
  cache.update = 80e9;
  cache.zero = 60e9;
  roofs.levels.insert(roofs.levels.begin(), cache);
  PhaseWork w;
  w.bytes_read = 1e6;
  w.bytes_written = 3e6;  // 1e6 allocated, 1e6 zeroed, 1e6 to lines read first
  w.bytes_allocated = 1e6;
  w.bytes_zeroed = 1e6;
  w.working_set = 200 << 10;
  CHECK(roofline::fitting_level(roofs, w.working_set).level.name == "L3");
  CHECK(roofline::memory_seconds(roofs, w) ==
        Approx(1e6 / 100e9 + 1e6 / 50e9 + 1e6 / 60e9 + 1e6 * (2 / 80e9 - 1 / 100e9)));
  // Inside the reported 1 MiB but above the 256 KiB the roof was measured on: memory's.
  w.working_set = 512 << 10;
  CHECK(roofline::fitting_level(roofs, w.working_set).level.name == "memory");
  // A private cache holds what it reports.
  roofs.levels.front().level.shared = false;
  CHECK(roofline::fitting_level(roofs, w.working_set).level.name == "L3");
  roofs.levels.front().level.shared = true;
  // In memory, but the L3 can still hold 256 KiB of the 512: half the bytes at its roofs.
  const double in_cache = 1e6 / 100e9 + 1e6 / 50e9 + 1e6 / 60e9 + 1e6 * (2 / 80e9 - 1 / 100e9);
  const double in_memory = 1e6 / 10e9 + 1e6 / 5e9 + 1e6 / 20e9 + 1e6 * (2 / 8e9 - 1 / 10e9);
  CHECK(roofline::memory_seconds(roofs, w) == Approx(0.5 * in_cache + 0.5 * in_memory));
  // An update alone (each line read, then written back) runs exactly at its own roofs, the
  // share the L3 can hold at the L3's.
  PhaseWork update;
  update.bytes_read = update.bytes_written = 1e6;
  update.working_set = 1e6;
  const double share = double(256 << 10) / 1e6;
  CHECK(roofline::memory_seconds(roofs, update) ==
        Approx(share * 2e6 / 80e9 + (1 - share) * 2e6 / 8e9));
}

TEST_CASE("roofline: one thread waits for nothing, and the largest term holds a phase",
          "[roofline]") {
  const roofline::Roofs roofs = hand_roofs(2);
  // The adaptive team's step on one thread: its barriers are counted, and cost nothing.
  CHECK(roofline::waiting_seconds(roofs, 1, 3, 100) == 0.0);
  CHECK(roofline::waiting_seconds(roofs, 2, 3, 100) == Approx(3 * 4e-6 + 100 * 1e-6));
  CHECK(roofline::waiting_seconds(roofs, 0, 3, 100) == Approx(3 * 4e-6 + 100 * 1e-6));
  CHECK(std::string(roofline::held_by(2.0, 1.0, 0.5)) == "bytes");
  CHECK(std::string(roofline::held_by(1.0, 2.0, 0.5)) == "flops");
  CHECK(std::string(roofline::held_by(1.0, 2.0, 3.0)) == "waiting");
}

TEST_CASE(
    "roofline: likwid-bench runs as long as asked or a second if longer, set by its iterations",
    "[roofline]") {
  // 1 MiB a thread at an expected 10 GB/s for the team of 2, a run of 0.1 s raised to
  // kLikwidRunSeconds (1 s): each of the two processes 5 GB, 1 MiB an iteration, 4768. -s would
  // take whole seconds only ("0.5" is none, and likwid-bench then runs its least, ten).
  using fem::roofline::likwid_command;
  using fem::roofline::LikwidKernel;
  const std::string load = likwid_command(LikwidKernel::load, 1 << 20, 2, 0.1, 10e9);
  // One process of one thread per CPU, each on its own MiB.
  CHECK(load.find(" -W N:1024kB:1 ") != std::string::npos);
  CHECK(load.find(" -W N:1024kB:1 ", load.find(" -W N:1024kB:1 ") + 1) != std::string::npos);
  CHECK(load.find("taskset -c ") != std::string::npos);
  CHECK(load.find(" -i 4768 ") != std::string::npos);
  CHECK(load.find(" -s ") == std::string::npos);
  // A run of 2 s, longer than the least.
  CHECK(likwid_command(LikwidKernel::load, 1 << 20, 2, 2.0, 10e9).find(" -i 9536 ") !=
        std::string::npos);
  // peakflops: 30 flops an element of 8 bytes, 16 KiB a thread, 100 Gflop/s on 1 thread.
  const std::string peak = likwid_command(LikwidKernel::peak, 16 << 10, 1, 0.1, 100e9);
  CHECK(peak.find(" -i 1627604 ") != std::string::npos);
  // Never fewer than likwid-bench's own least.
  CHECK(likwid_command(LikwidKernel::store, 1 << 20, 1, 0.1, 1.0).find(" -i 10 ") !=
        std::string::npos);
}
