// The steps of a benchmark: `warmup` unmeasured ones (the first allocates the steppers'
// buffers), then `steps` measured ones, with a line of progress at every fifth of the run.
#pragma once

#include <algorithm>

namespace fem::bench {

struct Schedule {
  int warmup = 10, steps = 100;

  int total() const { return warmup + steps; }
  bool measured(int k) const { return k >= warmup; }
  // After step k (from 0): another fifth of the run is done.
  bool reports(int k) const { return (k + 1) % std::max(1, total() / 5) == 0; }
};

}  // namespace fem::bench
