// Chapter 10: the refresh rule (see refresh_rule.hpp).
#include "chapters/10_multigrid/refresh_rule.hpp"

#include <algorithm>

namespace fem::ch10 {

bool RefreshRule::decide(bool coarse_levels_exist) {
  const int last = cycles_;
  cycles_ = 0;
  ++factorizations_;
  if (measure_next_ && factorizations_ > 2) {
    cycles_after_refresh_ = last;
    measure_next_ = false;
  }
  ++since_refresh_;
  const bool grown =
      settings_.growth > 0.0 && !measure_next_ && last > settings_.growth * cycles_after_refresh_;
  refreshed_ = !coarse_levels_exist || since_refresh_ >= settings_.every || grown;
  if (refreshed_) {
    since_refresh_ = 0;
    ++refreshes_;
    measure_next_ = true;
  }
  return refreshed_;
}

void RefreshRule::count_cycle() {
#pragma omp master
  ++cycles_;  // read by the next factorization, many barriers later
}

}  // namespace fem::ch10
