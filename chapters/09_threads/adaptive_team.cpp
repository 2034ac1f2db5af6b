// The team that measures itself: see adaptive_team.hpp.
#include "chapters/09_threads/adaptive_team.hpp"

#include <algorithm>

#include "common/statistics.hpp"
#include "common/threads.hpp"

namespace fem::ch09 {

int AdaptiveTeam::next(int given) {
  // A count the user asked for is the one that steps (common/threads.hpp): no choice then.
  chosen_ = enabled_ && given > 1 && !thread_count_asked();
  probing_ = false;
  if (!chosen_) return team_ = given;  // nothing to choose: record() ignores this step
  if (given != given_) {               // a new count from the program: start over with it
    given_ = current_ = given;
    period_ = until_probe_ = kFirstPeriod;
    recorded_ = 0;
  }
  // A probe only against a full window: the median of kWindow steps, not one noisy step.
  probing_ = until_probe_ <= 0 && recorded_ >= kWindow;
  team_ = probing_ ? (current_ == 1 ? given_ : 1) : current_;
  return team_;
}

void AdaptiveTeam::record(double seconds) {
  if (!chosen_) return;
  if (probing_) {
    if (seconds < kGain * usual()) {  // clearly faster: switch, and fill a new window
      current_ = team_;
      recorded_ = 0;
      period_ = kFirstPeriod;
      ++switches_;
    } else {
      period_ = std::min(2 * period_, kMaxPeriod);
      reference_ = usual();
    }
    until_probe_ = period_;
    return;
  }
  window_[recorded_ % kWindow] = seconds;
  ++recorded_;
  --until_probe_;
  if (recorded_ < kWindow) return;
  // The usual time has moved by half since the last decision, the way a busy machine moves it
  // (a team slower, one thread faster): probe at once rather than after the long period of a
  // steady machine. (The other way, the probe would be a step on a busy machine's team.)
  const double now = usual();
  const bool moved = current_ > 1 ? now > kChange * reference_ : kChange * now < reference_;
  if (recorded_ > kWindow && moved) {
    until_probe_ = 0;
    period_ = kFirstPeriod;
    reference_ = now;
  } else if (recorded_ == kWindow) {  // a full window after a switch
    reference_ = now;
  }
}

double AdaptiveTeam::usual() const {
  double sorted[kWindow];
  std::copy(window_, window_ + kWindow, sorted);
  return median_in_place(sorted, sorted + kWindow);
}

}  // namespace fem::ch09
