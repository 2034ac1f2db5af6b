// Chapter 10: the refresh rule. The coarse matrices live across steps: the finest level always
// uses the matrix it is given (so the V-cycle stays symmetric positive definite), the coarse
// ones are recomputed every k-th step, or earlier when the V-cycles per solve grow.
#pragma once

namespace fem::ch10 {

struct RefreshSettings {
  // Recomputed every every-th step (1: every step), and earlier when the last solve took more
  // than growth times the V-cycles of the solve right after the last refresh (0: never
  // earlier).
  int every = 20;
  double growth = 1.25;
};

// Called on one thread between barriers: it reads only V-cycle counts, the same for any thread
// count, so the decision (and the state) is too. Its yardstick is the count of the solve right
// after a refresh; after the first refresh, of the second solve, since the first one starts
// cold (no guess from earlier steps).
class RefreshRule {
 public:
  explicit RefreshRule(const RefreshSettings& settings) : settings_(settings) {}

  // At every factorization: whether it recomputes the coarse levels (always when they do not
  // exist yet).
  bool decide(bool coarse_levels_exist);
  // One V-cycle, by every thread of a team or outside one (the team's master counts).
  void count_cycle();

  // Refreshes so far, and whether the last factorization was one.
  long long refreshes() const { return refreshes_; }
  bool refreshed() const { return refreshed_; }

 private:
  RefreshSettings settings_;
  bool refreshed_ = false;
  long long refreshes_ = 0;
  long long factorizations_ = 0;
  int since_refresh_ = 0;         // factorizations since the last refresh
  int cycles_ = 0;                // V-cycles since the last factorization (the last solve's)
  int cycles_after_refresh_ = 0;  // V-cycles of the solve right after the last refresh
  bool measure_next_ = false;     // the next factorization reads the yardstick
};

}  // namespace fem::ch10
