// Chapter 10's level interface (v_cycle.hpp): the probe finds every kernel of chapter 10's and
// chapter 12's levels, and says which one a level type lacks; deriving from PolynomialLevel is
// what brings chapter 10's polynomial smoothing steps and residual, and nothing else does.
#include "catch2_compat.hpp"
#include "chapters/10_multigrid/prolongator.hpp"
#include "chapters/10_multigrid/v_cycle.hpp"
#include "chapters/12_half_the_bytes/reduced_kernels.hpp"

using namespace fem;

namespace probe {

// A level with its source and vectors but none of the kernels.
struct Bare {
  static constexpr int block_size = 3;
  const ch10::Level<3>* source = nullptr;
  struct {
    std::vector<double> weights;
  } smoother;
  ch10::WorkVectors<double> vectors;
};
inline const ch10::Level<3>& source_level(const Bare& level) { return *level.source; }

// The same, declared a polynomial level: chapter 10's smoothing steps and residual apply.
struct Polynomial : Bare, ch10::PolynomialLevel {};

}  // namespace probe

namespace {

using namespace ch10::level_interface;
using Doubles = Eigen::VectorXd;

}  // namespace

TEST_CASE("ch12: the level interface finds chapter 10's and chapter 12's kernels", "[ch12]") {
  using ch10::kModes;
  STATIC_REQUIRE(ch10::check_level_kernels<ch10::Level<3>, ch10::Level<kModes>, Doubles>());
  STATIC_REQUIRE(ch10::check_level_kernels<ch10::Level<kModes>, ch10::Level<kModes>, Doubles>());
  using FloatFine = ch12::ReducedLevel<float, 3>;
  using FloatCoarse = ch12::ReducedLevel<float, kModes>;
  STATIC_REQUIRE(ch10::check_level_kernels<FloatFine, FloatCoarse, Eigen::VectorXf>());
  using WideFine = ch12::ReducedLevel<double, 3>;
  using WideCoarse = ch12::ReducedLevel<double, kModes>;
  STATIC_REQUIRE(ch10::check_level_kernels<WideFine, WideCoarse, Doubles>());
  // The probe reads the vector type: float levels do not run a cycle on doubles.
  STATIC_REQUIRE_FALSE(has_vectors<FloatFine, Doubles>::value);
  STATIC_REQUIRE_FALSE(has_solve_coarsest<FloatFine, Doubles>::value);
}

TEST_CASE("ch12: the level interface names what a level type lacks", "[ch12]") {
  using probe::Bare;
  using probe::Polynomial;
  STATIC_REQUIRE(has_source_level<Bare>::value);
  STATIC_REQUIRE(has_vectors<Bare, Doubles>::value);
  // Chapter 10's generic kernels are not found for a level that does not ask for them...
  STATIC_REQUIRE_FALSE(has_smoothing_steps<Bare>::value);
  STATIC_REQUIRE_FALSE(has_smooth<Bare, Doubles>::value);
  STATIC_REQUIRE_FALSE(has_residual<Bare, Doubles>::value);
  // ... and are for one derived from PolynomialLevel; the transfers and the coarsest solve stay
  // the level's own to bring.
  STATIC_REQUIRE(has_smoothing_steps<Polynomial>::value);
  STATIC_REQUIRE(has_smooth<Polynomial, Doubles>::value);
  STATIC_REQUIRE(has_residual<Polynomial, Doubles>::value);
  STATIC_REQUIRE_FALSE(has_restrict_rows<Polynomial, Polynomial>::value);
  STATIC_REQUIRE_FALSE(has_prolong_rows<Polynomial, Polynomial, Doubles>::value);
  STATIC_REQUIRE_FALSE(has_solve_coarsest<Polynomial, Doubles>::value);
  STATIC_REQUIRE_FALSE(has_source_level<int>::value);
}
