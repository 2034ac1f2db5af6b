// The steps of a benchmark: `warmup` unmeasured ones (the first allocates the steppers'
// buffers), then `steps` measured ones, with a line of progress at every fifth of the run.
// The chapters take turns of `turn` steps: within a turn a chapter steps as it does in an
// interactive run, its data in the caches and its thread team awake; one step of each in
// turn would measure, on a mesh whose data fit in the caches, the refill of the caches and
// the waking of the team that the other chapters' steps cause, not the chapter's step.
#pragma once

#include <algorithm>
#include <csignal>

namespace fem::bench {

struct Schedule {
  int warmup = 10, steps = 100;
  static constexpr int turn = 10;

  int total() const { return warmup + steps; }
  bool measured(int k) const { return k >= warmup; }
  // After step k (from 0): another fifth of the run is done.
  bool reports(int k) const { return (k + 1) % std::max(1, total() / 5) == 0; }
};

// Ctrl-C (SIGINT) or SIGTERM, set by fem_bench's handler (main.cpp) and checked after every
// step: the run stops between steps and unwinds, so that its folder's lock is released and an
// earlier bench.json stays as it was, with a message (it once died by the signal, silent, its
// lock left behind).
inline volatile std::sig_atomic_t interrupted = 0;
struct Interrupted {};  // not a std::exception: main() answers it with 130, as a shell does
inline void stop_if_interrupted() {
  if (interrupted) throw Interrupted{};
}

}  // namespace fem::bench
