// Chapter 14's kernels as parts, before a stepper runs them: the pair lanes' fine residual
// (its product and a subtraction) equals the padded columns' (the float V-cycle's own kernels) to
// the bit on the poster plate's and the test beam's patterns, and so does the smoothing step but
// for the one rounding the compiler may place differently in its update; the double product equals
// the block rows' within a few ulps; each is the same to the bit on 1 and 2 threads, and a call
// allocates nothing.
#include <cfloat>
#include <cmath>
#include <cstring>
#include <memory>

#include "catch2_compat.hpp"
#include "chapters/09_threads/parallel.hpp"
#include "chapters/09_threads/parallel_pcg.hpp"
#include "chapters/10_multigrid/v_cycle.hpp"
#include "chapters/12_half_the_bytes/reduced_kernels.hpp"
#include "chapters/12_half_the_bytes/stepper.hpp"
#include "chapters/14_every_lane/fine_smoothing.hpp"
#include "chapters/14_every_lane/lane_product.hpp"
#include "chapters/14_every_lane/row_pairs.hpp"
#include "common/alloc_counter.hpp"
#include "common/threads.hpp"
#include "support.hpp"

// The narrow build of these tests (test_ch14_kernels_narrow, -march=x86-64) names its test
// cases apart, so that each ctest test runs the test case of its own name.
#ifndef FEM_CH14_SUFFIX
#define FEM_CH14_SUFFIX ""
#endif

using namespace fem;

namespace {

// A float-V-cycle stepper after three steps on `mesh` (its levels hold a step's numbers).
std::unique_ptr<ch12::HalfBytesStepper> stepped(const std::string& mesh) {
  static std::vector<std::unique_ptr<Scene>> scenes;  // the stepper keeps a reference
  scenes.push_back(
      std::make_unique<Scene>(make_scene("cantilever", load_mesh(test::mesh_path(mesh)))));
  auto stepper = std::make_unique<ch12::HalfBytesStepper>(*scenes.back(), SolverSettings{});
  State state = rest_state(*scenes.back());
  for (int k = 0; k < 3; ++k) stepper->step(state);
  return stepper;
}

ch12::ReducedLevel<float, 3>& fine_level(ch12::HalfBytesStepper& stepper) {
  return stepper.preconditioner().v_cycle().fine_level();
}

// body() by every thread of a team of `threads`.
template <class Body>
void on_team(int threads, Body&& body) {
  const ThreadCountScope team(openmp_enabled() ? threads : 1);
  ch09::run_parallel(body);
}

template <class Vector>
bool same_bits(const Vector& a, const Vector& b) {
  return a.size() == b.size() &&
         std::memcmp(a.data(), b.data(), sizeof(typename Vector::Scalar) * a.size()) == 0;
}

// The level's vectors a smoothing step or a residual writes, to restore and compare.
struct Written {
  Eigen::VectorXf y, direction, residual;
  explicit Written(const ch12::ReducedLevel<float, 3>& level)
      : y(level.vectors.y), direction(level.vectors.direction), residual(level.vectors.residual) {}
  void restore(ch12::ReducedLevel<float, 3>& level) const {
    level.vectors.y = y;
    level.vectors.direction = direction;
    level.vectors.residual = residual;
  }
};

// Step k (from zero or from x) and the residual of x, by the padded columns (lanes null) or
// by the lanes, on a team of `threads`: what they write.
template <class Lanes>
Written run_fine(ch12::ReducedLevel<float, 3>& level, Lanes* lanes, int k, bool from_zero,
                 int threads) {
  const Written start(level);
  const auto& part = source_level(level).rows.part;
  auto& v = level.vectors;
  const Eigen::VectorXf* in = from_zero ? nullptr : &v.x;
  on_team(threads, [&] {
    ch09::for_parts(part, true, [&](int first, int last) {
      if (lanes)
        ch14::smooth_rows(*lanes, k, first, last, v.b, in, v.y);
      else
        ch10::smooth(level, k, first, last, v.b, in, v.y, true);
    });
    ch09::for_parts(part, true, [&](int first, int last) {
      if (lanes)
        ch14::residual_rows(*lanes, first, last, v.b, v.x);
      else
        ch10::residual(level, first, last, v.b, v.x);
    });
  });
  const Written out(level);
  start.restore(level);
  return out;
}

}  // namespace

// The largest difference between two vectors, against the largest entry of a third.
double worst(const Eigen::VectorXf& a, const Eigen::VectorXf& b, const Eigen::VectorXf& scale) {
  return (a - b).cwiseAbs().maxCoeff() / scale.cwiseAbs().maxCoeff();
}

// The residual b - A x is the product and one subtraction: the product's sums to the bit.
TEST_CASE("ch14: the lanes' fine residual is the padded columns' to the bit" FEM_CH14_SUFFIX,
          "[ch14]") {
  for (const std::string mesh : {"plate_poster.msh", "test_beam.msh"}) {
    INFO(mesh);
    auto stepper = stepped(mesh);
    auto& level = fine_level(*stepper);
    ch14::LaneFineLevel pairs(level);
    ch14::RowPairFineLevel row_pairs(level);
    pairs.fill(0, pairs.blocks.rows());
    row_pairs.fill(0, row_pairs.blocks.rows());
    const Written expected = run_fine<ch14::LaneFineLevel>(level, nullptr, 0, false, 1);
    for (const int threads : {1, 2}) {
      INFO(threads << " thread(s)");
      CHECK(same_bits(run_fine(level, &pairs, 0, false, threads).residual, expected.residual));
      CHECK(same_bits(run_fine(level, &row_pairs, 0, false, threads).residual, expected.residual));
    }
  }
}

// The layouts differ in how they hold the blocks, not in what they compute: the same products
// (to the bit, above) and the update's multiply-add spelled out, so the same bits in every
// step, and the stepper may run whichever layout is faster on the thread count it has.
TEST_CASE("ch14: padded, packed and row pairs smooth to the same bits" FEM_CH14_SUFFIX, "[ch14]") {
  for (const std::string mesh : {"plate_poster.msh", "test_beam.msh"}) {
    auto stepper = stepped(mesh);
    auto& level = fine_level(*stepper);
    ch14::LaneFineLevel padded(level);
    ch14::PackedFineLevel packed(level);
    ch14::RowPairFineLevel row_pairs(level);
    padded.fill(0, padded.blocks.rows());
    packed.fill(0, packed.blocks.rows());
    row_pairs.fill(0, row_pairs.blocks.rows());
    const int steps = ch10::smoothing_steps(level);
    for (const int k : {0, 1, steps - 1})
      for (const bool from_zero : {true, false})
        for (const int threads : {1, 2}) {
          INFO(mesh << ", step " << k << (from_zero ? " from zero" : " from x") << ", " << threads
                    << " thread(s)");
          const Written one = run_fine(level, &padded, k, from_zero, threads);
          for (const Written& other : {run_fine(level, &packed, k, from_zero, threads),
                                       run_fine(level, &row_pairs, k, from_zero, threads)}) {
            CHECK(same_bits(other.y, one.y));
            CHECK(same_bits(other.direction, one.direction));
            CHECK(same_bits(other.residual, one.residual));
          }
        }
  }
}

namespace {

// Steps 0, 1 and the last, from zero and from x, by `Lanes` against the padded columns.
template <class Lanes>
void check_smoothing(const std::string& mesh) {
  auto stepper = stepped(mesh);
  auto& level = fine_level(*stepper);
  REQUIRE(stepper->preconditioner().multigrid().levels() >= 2);
  Lanes lanes(level);
  lanes.fill(0, lanes.blocks.rows());
  const int steps = ch10::smoothing_steps(level);
  const Eigen::VectorXf direction = level.vectors.direction;
  for (const int k : {0, 1, steps - 1})
    for (const bool from_zero : {true, false}) {
      INFO(mesh << ", step " << k << (from_zero ? " from zero" : " from x"));
      const Written expected = run_fine<Lanes>(level, nullptr, k, from_zero, 1);
      const Written one = run_fine(level, &lanes, k, from_zero, 1);
      const bool exact = from_zero || k == 0;
      const float alpha = level.smoother.weights[2 * k];
      const double terms = std::abs(alpha) * direction.cwiseAbs().maxCoeff() +
                           expected.direction.cwiseAbs().maxCoeff();
      CHECK((exact ? same_bits(one.direction, expected.direction)
                   : (one.direction - expected.direction).cwiseAbs().maxCoeff() <=
                         2.0 * FLT_EPSILON * terms));
      CHECK((exact ? same_bits(one.y, expected.y)
                   : worst(one.y, expected.y, expected.y) <= 4.0 * FLT_EPSILON));
      const Written two = run_fine(level, &lanes, k, from_zero, 2);
      CHECK(same_bits(two.y, one.y));
      CHECK(same_bits(two.direction, one.direction));
    }
}

}  // namespace

// The step's update d = alpha d + beta D^-1 r is one multiply-add and a multiply: GCC fuses
// one of the two multiplies with the add, and which one depends on the code around it, not
// on the source. From zero, and in the first step, there is no alpha d: to the bit. After, to
// the one rounding: within a float epsilon of the terms.
TEST_CASE(
    "ch14: the lanes' smoothing step is the padded columns' but for the update's one "
    "rounding, the same on 1 and 2 threads" FEM_CH14_SUFFIX,
    "[ch14]") {
  for (const std::string mesh : {"plate_poster.msh", "test_beam.msh"}) {
    SECTION("pair lanes " + mesh) { check_smoothing<ch14::LaneFineLevel>(mesh); }
    SECTION("row pairs " + mesh) { check_smoothing<ch14::RowPairFineLevel>(mesh); }
    SECTION("packed pairs " + mesh) { check_smoothing<ch14::PackedFineLevel>(mesh); }
  }
}

namespace {

// q = A p by `Lanes` on 1 and 2 threads against the block rows', entry by entry within 1e-15
// of the sum of its products' magnitudes, |A| |p|.
template <class Lanes>
void check_product(const std::string& mesh) {
  auto stepper = stepped(mesh);
  const ch07::BlockSparseMatrix& A = stepper->system_matrix();
  Lanes lanes(A);
  lanes.fill(A, 0, A.block_rows());
  const ch09::RowChunks chunks(A);
  const Eigen::VectorXd p = Eigen::VectorXd::Random(3 * A.block_rows());
  Eigen::VectorXd expected(p.size()), scale(p.size());
  A.multiply(p, expected);
  ch07::BlockSparseMatrix absolute = A;
  for (auto& block : absolute.blocks) block = block.cwiseAbs();
  absolute.multiply(p.cwiseAbs(), scale);
  Eigen::VectorXd one(p.size());
  for (const int threads : {1, 2}) {
    Eigen::VectorXd q = Eigen::VectorXd::Constant(p.size(), -1.0);
    on_team(threads, [&] {
      for (const int c : ch09::StaticShare(chunks.count()))
        lanes.multiply_rows(p, q, chunks.start[c], chunks.start[c + 1]);
    });
    CHECK(((q - expected).cwiseAbs().array() <= 1e-15 * scale.array()).all());
    if (threads == 1)
      one = q;
    else
      CHECK(same_bits(q, one));
  }
}

}  // namespace

TEST_CASE(
    "ch14: the pair lanes' double product is the block rows' within a few ulps, the same "
    "on 1 and 2 threads" FEM_CH14_SUFFIX,
    "[ch14]") {
  for (const std::string mesh : {"plate_poster.msh", "test_beam.msh"}) {
    SECTION("packed " + mesh) { check_product<ch14::LaneProduct>(mesh); }
    SECTION("padded " + mesh) { check_product<ch14::PaddedLaneProduct>(mesh); }
  }
}

// The lanes' fine level is a level of the V-cycle: a whole cycle on it (with the float coarse
// levels below) is the float V-cycle's to float rounding, and the same on 1 and 2 threads.
TEST_CASE(
    "ch14: a whole V-cycle on the lanes' fine level is the float V-cycle's to "
    "rounding" FEM_CH14_SUFFIX,
    "[ch14]") {
  auto stepper = stepped("plate_poster.msh");
  ch12::ReducedVCycle<float>* cycle = &stepper->preconditioner().v_cycle();
  auto& fine = cycle->fine_level();
  auto& coarse = cycle->coarse_levels();
  ch14::LaneFineLevel lanes(fine);
  lanes.fill(0, lanes.blocks.rows());
  const Eigen::VectorXf r = fine.vectors.b;
  Eigen::VectorXf expected(r.size()), one(r.size()), two(r.size());
  on_team(1, [&] { ch10::v_cycle(fine, coarse, 0, r, expected, true); });
  on_team(1, [&] { ch10::v_cycle(lanes, coarse, 0, r, one, true); });
  on_team(2, [&] { ch10::v_cycle(lanes, coarse, 0, r, two, true); });
  CHECK((one - expected).norm() <= 1e-5 * expected.norm());
  CHECK(same_bits(one, two));
}

TEST_CASE("ch14: the lanes' kernels allocate nothing per call, on 2 threads" FEM_CH14_SUFFIX,
          "[ch14]") {
  FEM_REQUIRE_ALLOCATION_COUNTER();
  auto stepper = stepped("plate_poster.msh");
  auto& level = fine_level(*stepper);
  ch14::LaneFineLevel fine(level);
  const ch07::BlockSparseMatrix& A = stepper->system_matrix();
  ch14::LaneProduct product(A);
  const ch09::RowChunks chunks(A);
  Eigen::VectorXd p = Eigen::VectorXd::Ones(3 * A.block_rows()), q = p;
  const auto& part = source_level(level).rows.part;
  auto& v = level.vectors;
  const auto calls = [&] {
    ch09::for_parts(part, true, [&](int first, int last) { fine.fill(first, last); });
    ch09::for_parts(part, true, [&](int first, int last) {
      ch14::smooth_rows(fine, 1, first, last, v.b, &v.x, v.y);
    });
    ch09::for_parts(part, true,
                    [&](int first, int last) { ch14::residual_rows(fine, first, last, v.b, v.y); });
    for (const int c : ch09::StaticShare(chunks.count())) {
      product.fill(A, chunks.start[c], chunks.start[c + 1]);
      product.multiply_rows(p, q, chunks.start[c], chunks.start[c + 1]);
    }
  };
  on_team(2, calls);  // the team is made once (the runtime keeps it)
  const alloc::Scope scope;
  for (int call = 0; call < 3; ++call) on_team(2, calls);
  CHECK(scope.allocations() == 0);
}
