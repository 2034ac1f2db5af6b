#include "chapters/14_every_lane/lane_v_cycle.hpp"

#include <algorithm>
#include <chrono>

#include "chapters/09_threads/parallel.hpp"
#include "chapters/10_multigrid/v_cycle.hpp"

namespace fem::ch14 {

namespace {

int team_size() {
#ifdef _OPENMP
  return omp_get_num_threads();
#else
  return 1;
#endif
}

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

LaneVCycle::LaneVCycle(ch12::ReducedVCycle<float>& reduced, ch10::Multigrid& multigrid,
                       std::optional<Layout> forced)
    : reduced_(reduced),
      multigrid_(multigrid),
      lanes_(multigrid.levels() > 1),
      forced_(forced),
      current_(forced.value_or(Layout::padded)),
      padded_(reduced.fine_level()),
      packed_(reduced.fine_level()),
      r_(Eigen::VectorXf::Zero(multigrid.fine_level().dofs())),
      s_(Eigen::VectorXf::Zero(multigrid.fine_level().dofs())) {
  measured_.fill(-1);
}

std::optional<Layout> LaneVCycle::measured(int threads) const {
  const signed char m = measured_[std::clamp(threads, 1, kTeams)];
  if (m < 0) return std::nullopt;
  return Layout(m);
}

const LaneVCycle::Seconds& LaneVCycle::trial_seconds(int threads) const {
  return trials_[std::clamp(threads, 1, kTeams)];
}

// The trial's order: padded, packed, packed, padded, padded, packed, ... (each pair of turns
// reversed), so that a drift of the machine's speed over the trial weighs on both alike.
Layout LaneVCycle::turn(int k) { return ((k + 1) / 2) % 2 == 0 ? Layout::padded : Layout::packed; }

// The layout whose median time was the shorter: a median, not a mean, because one turn
// disturbed by the machine (or the first of each, whose fill touches its pages for the first
// time) would move a mean by more than the layouts differ.
Layout LaneVCycle::faster(Seconds seconds) {
  const auto median = [](double* first) {
    std::nth_element(first, first + kTrials / 2, first + kTrials);
    return first[kTrials / 2];
  };
  return median(seconds.data() + kTrials) < median(seconds.data()) ? Layout::packed
                                                                   : Layout::padded;
}

// Each thread fills the row blocks it smooths (the same static share of the same parts).
void LaneVCycle::fill(Layout layout) {
  ch09::on_one_thread(true, [&] { current_ = layout; });
  with_fine_level([&](auto& fine) {
    ch09::for_parts(source_level(fine).rows.part, true,
                    [&](int first, int last) { fine.fill(first, last); });
  });
}

// Each turn: one layout filled from this step's blocks and three V-cycles run from it, the
// time from the fill's start to the last cycle's end (the barrier in on_one_thread). The
// cycles' input is a fixed vector (their cost does not depend on its values); apply
// overwrites r_ and s_ before they are read again.
void LaneVCycle::trial(int team) {
  Seconds& seconds = trials_[team];
  ch09::on_one_thread(true, [&] { r_.setOnes(); });
  for (int k = 0; k < 2 * kTrials; ++k) {
    ch09::on_one_thread(true, [&] { started_ = now_seconds(); });
    fill(turn(k));
    // Not through multigrid_.apply, which counts its cycles for the refresh rule: the trial's
    // would change when the hierarchy is rebuilt, so the state would depend on the trial.
    for (int c = 0; c < kCycles; ++c)
      with_fine_level(
          [&](auto& fine) { ch10::v_cycle(fine, reduced_.coarse_levels(), 0, r_, s_, true); });
    ch09::on_one_thread(true, [&] {
      seconds[(current_ == Layout::packed ? kTrials : 0) + k / 2] = now_seconds() - started_;
    });
  }
  ch09::on_one_thread(true, [&] { measured_[team] = static_cast<signed char>(faster(seconds)); });
}

void LaneVCycle::prepare(const ch07::BlockSparseMatrix& A) {
  reduced_.prepare(A);
  if (!lanes_) return;
  const int team = std::clamp(team_size(), 1, kTeams);
  if (!forced_ && measured_[team] < 0) trial(team);
  fill(forced_ ? *forced_ : Layout(measured_[team]));
}

void LaneVCycle::apply(const Eigen::VectorXd& r, Eigen::VectorXd& s) {
  if (!lanes_) {
    reduced_.apply(r, s);
    return;
  }
  const std::vector<int>& part = reduced_.fine_level().source->rows.part;
  ch09::for_parts(part, true, [&](int first, int last) { ch12::convert_rows(r, r_, first, last); });
  with_fine_level([&](auto& fine) { multigrid_.apply(fine, reduced_.coarse_levels(), r_, s_); });
  ch09::for_parts(part, true, [&](int first, int last) { ch12::convert_rows(s_, s, first, last); });
}

}  // namespace fem::ch14
