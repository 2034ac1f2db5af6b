// The roofline's counts against the data structures they count, computed here independently
// from the stepper's objects; and the working sets of the roofs. No timing is asserted: the
// roofs' second measurement is reported by the lesson (fem_lessons roofline), not tested.
#include "apps/roofline/bandwidth.hpp"
#include "apps/roofline/work.hpp"
#include "catch2_compat.hpp"
#include "chapters/01_naive/stepper.hpp"
#include "chapters/07_block_sparse/stepper.hpp"
#include "chapters/10_multigrid/report.hpp"
#include "chapters/10_multigrid/stepper.hpp"
#include "chapters/registry.hpp"
#include "support.hpp"

using namespace fem;

namespace {

const roofline::PhaseWork& phase(const std::vector<roofline::PhaseWork>& work,
                                 const std::string& name) {
  for (const auto& w : work)
    if (w.phase == name) return w;
  FAIL("no phase " << name);
  return work.front();
}

}  // namespace

TEST_CASE("roofline: chapter 07's matrix bytes are its blocks and indices", "[roofline]") {
  const Scene scene = test::test_scene("cantilever");
  ch07::BlockSparseStepper stepper(scene, {});
  State state = rest_state(scene);
  stepper.step(state);
  const ch07::BlockSparseMatrix& A = stepper.system_matrix();
  const double expected =
      double(A.blocks.size()) * 72.0 + double(A.column.size() + A.row_start.size()) * 4.0;
  CHECK(roofline::matrix_bytes(A) == expected);
  // The solve streams the matrix, the block-Jacobi inverses and 11 vectors per product.
  const int it = stepper.profile().cg_iterations;
  std::string counted_as;
  const auto work = roofline::count_work(stepper, scene, it, counted_as);
  CHECK(counted_as == "07");
  const double n = 3.0 * scene.mesh.num_nodes();
  const double per_iteration = expected + scene.mesh.num_nodes() * 72.0 + 11 * n * 8;
  CHECK(phase(work, "solve").bytes == Approx((it + 1) * per_iteration));
  // The constraints: the blocks of constrained rows and columns, read and written.
  double blocks = 0;
  for (const NodeConstraint& c : scene.constraints)
    blocks += A.row_start[c.node + 1] - A.row_start[c.node];
  REQUIRE(blocks > 0);
  CHECK(phase(work, "constraints").bytes == Approx(4 * 72 * blocks + 2 * n * 8));
}

TEST_CASE("roofline: chapter 01's matrix bytes are Eigen's compressed storage", "[roofline]") {
  const Scene scene = test::test_scene("cantilever");
  ch01::NaiveStepper stepper(scene, {});
  State state = rest_state(scene);
  stepper.step(state);
  const Eigen::SparseMatrix<double>& dfdx = stepper.dfdx();
  REQUIRE(dfdx.isCompressed());
  const double expected = double(dfdx.nonZeros()) * (8 + 4) + double(dfdx.cols() + 1) * 4;
  CHECK(roofline::matrix_bytes(dfdx) == expected);
  // Every entry of df/dx is one of 3x3 blocks of the chapter 07 pattern on the same mesh.
  ch07::BlockSparseStepper blocks(scene, {});
  blocks.step(state);
  CHECK(double(dfdx.nonZeros()) == 9.0 * double(blocks.system_matrix().blocks.size()));
}

TEST_CASE("roofline: the V-cycle's levels are the hierarchy's matrices", "[roofline]") {
  const Scene scene = test::test_scene("cantilever");
  ch10::MultigridStepper stepper(scene, {});
  State state = rest_state(scene);
  stepper.step(state);
  const auto levels = roofline::multigrid_levels(stepper.multigrid());
  REQUIRE(int(levels.size()) == stepper.multigrid().levels());
  CHECK(levels.back().coarsest);
  for (std::size_t l = 0; l < levels.size(); ++l) {
    const auto A = ch10::level_matrix(stepper.multigrid(), int(l));  // an independent conversion
    const int b = levels[l].block;
    CHECK(double(levels[l].nodes * b) == double(A.rows()));
    CHECK(double(levels[l].blocks) * b * b >= double(A.nonZeros()));  // zero entries not stored
    if (!levels[l].coarsest)
      CHECK(double(levels[l].transfer) * b * ch10::kModes >=
            double(ch10::prolongator(stepper.multigrid(), int(l)).nonZeros()));
  }
  // A float V-cycle streams fewer bytes than a double one over the same levels.
  const int products = roofline::smoother_products(stepper.multigrid());
  CHECK(products >= 2);
  CHECK(roofline::v_cycle_work(levels, products, 4, true).bytes <
        roofline::v_cycle_work(levels, products, 8, false).bytes);
}

TEST_CASE("roofline: the registry's steppers are counted through their wrapper", "[roofline]") {
  const Scene scene = test::test_scene("cantilever");
  for (const ChapterInfo& c : chapters()) {
    if (!c.variant_of.empty()) continue;
    const auto stepper = c.make(scene, {});
    State state = rest_state(scene);
    stepper->step(state);
    std::string counted_as;
    const auto work = roofline::count_work(*stepper, scene, 1, counted_as);
    CHECK(counted_as == c.id.substr(0, 2));
    for (const auto& w : work) {
      CHECK(w.bytes > 0);
      CHECK(w.working_set <= w.bytes);
    }
  }
}

TEST_CASE("roofline: the roofs' working sets fit the levels they measure", "[roofline]") {
  const std::vector<roofline::CacheLevel> caches = {
      {1, 48 << 10, 1}, {2, 1 << 20, 1}, {3, 32 << 20, 2}};
  for (const int threads : {1, 2}) {
    const auto levels = roofline::memory_levels(caches, threads);
    REQUIRE(levels.size() == 4);
    for (std::size_t l = 0; l + 1 < levels.size(); ++l)
      CHECK(levels[l].working_set * 2 <= levels[l].capacity);
    // The shared L3 is split between the threads; memory is four times the largest cache.
    CHECK(levels[2].capacity == std::size_t(32 << 20) / threads);
    CHECK(levels.back().working_set * threads >= std::size_t(4) * (32 << 20));
  }
}
