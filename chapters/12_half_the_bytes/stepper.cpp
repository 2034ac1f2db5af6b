// Chapter 12: chapter 11's step with its V-cycle on float numbers and its element pass across
// elements (see stepper.hpp).
#include "chapters/12_half_the_bytes/stepper.hpp"

#include <algorithm>

namespace fem::ch12 {

namespace {

std::unique_ptr<ch09::Preconditioner> reduced_v_cycle(ch10::Multigrid& multigrid,
                                                      Arithmetic arithmetic) {
  if (arithmetic == Arithmetic::single) return std::make_unique<ReducedVCycle<float>>(multigrid);
  return std::make_unique<ReducedVCycle<double>>(multigrid);
}

}  // namespace

HalfBytesStepper::HalfBytesStepper(const Scene& scene, const SolverSettings& settings,
                                   Arithmetic arithmetic,
                                   const ch10::MultigridStepperSettings& multigrid)
    : NodeOrderStepper(scene, settings, ch11::Ordering::rcm, multigrid),
      arithmetic_(arithmetic),
      batched_(model_, scene_),
      v_cycle_(reduced_v_cycle(this->multigrid(), arithmetic)) {
  // Chapter 10's hierarchy, set up and prepared in double as before; the PCG now applies it
  // through the float copy.
  use_preconditioner(*v_cycle_, "12_half_the_bytes");
}

void HalfBytesStepper::element_pass(const State& state) {
  // Chapter 09's colour loop; inside a group, kLanes consecutive elements at a time, each
  // batch's terms scattered in element order, so the sums (and the state) are the same for
  // any thread count.
  auto& A = system_to_write();
  auto& b = rhs_to_write();
  batched_.end_pass(for_coloured_groups([&](int first, int last, long long& fallbacks) {
    BatchTerms terms;  // on this thread's stack: no allocation, no sharing
    for (int e = first; e < last; e += kLanes) {
      const int count = std::min(kLanes, last - e);
      batched_.terms(e, count, model_.tets, state, fallbacks, terms);
      for (int l = 0; l < count; ++l)
        scatter(terms, l, model_.tets[e + l], index_.element[e + l], A, b);
    }
  }));
}

}  // namespace fem::ch12
