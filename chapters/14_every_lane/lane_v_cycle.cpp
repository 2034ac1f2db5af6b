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

// Each thread fills the row blocks it smooths (the same static share of the same parts).
template <class Lanes>
void fill(Lanes& fine) {
  ch09::for_parts(source_level(fine).rows.part, true,
                  [&](int first, int last) { fine.fill(first, last); });
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

// The trial's order: padded, packed, packed, padded, padded, packed, ... (each pair of turns
// reversed), so that a drift of the machine's speed over the trial weighs on both alike.
Layout LaneVCycle::Trial::next() const {
  return ((steps + 1) / 2) % 2 == 0 ? Layout::padded : Layout::packed;
}

// The layout whose median step was the shorter: a median, not a mean, because one step
// disturbed by the machine (or the first, with data still in the other layout's place) would
// move a mean by more than the layouts differ.
Layout LaneVCycle::Trial::faster() {
  const auto median = [](double* first) {
    std::nth_element(first, first + kTrials / 2, first + kTrials);
    return first[kTrials / 2];
  };
  return median(seconds.data() + kTrials) < median(seconds.data()) ? Layout::packed
                                                                   : Layout::padded;
}

void LaneVCycle::Trial::record(Layout layout, double time) {
  seconds[(layout == Layout::packed ? kTrials : 0) + steps / 2] = time;
  ++steps;
}

// By one thread, at the next prepare: the step's end is its last V-cycle's, since only then
// is it known to be the last. A step whose solve ran no V-cycle (a guess already converged)
// is not a trial's.
void LaneVCycle::end_trial_step() {
  if (trial_team_ == 0 || ended_ <= started_) return;
  Trial& trial = trials_[trial_team_];
  trial.record(current_, ended_ - started_);
  if (trial.steps == 2 * kTrials) measured_[trial_team_] = static_cast<signed char>(trial.faster());
}

void LaneVCycle::prepare(const ch07::BlockSparseMatrix& A) {
  reduced_.prepare(A);
  if (!lanes_) return;
  const int team = std::clamp(team_size(), 1, kTeams);
  ch09::on_one_thread(true, [&] {
    end_trial_step();
    const bool trial = !forced_ && measured_[team] < 0;
    trial_team_ = trial ? team : 0;
    current_ = forced_ ? *forced_ : trial ? trials_[team].next() : Layout(measured_[team]);
    started_ = ended_ = now_seconds();
  });
  if (current_ == Layout::padded)
    fill(padded_);
  else
    fill(packed_);
}

// A V-cycle of a trial's step ends after every thread's share (the last convert_rows ends in
// the team's barrier); one thread reads the clock.
void LaneVCycle::apply(const Eigen::VectorXd& r, Eigen::VectorXd& s) {
  if (!lanes_) {
    reduced_.apply(r, s);
    return;
  }
  const std::vector<int>& part = reduced_.fine_level().source->rows.part;
  ch09::for_parts(part, true, [&](int first, int last) { ch12::convert_rows(r, r_, first, last); });
  with_fine_level([&](auto& fine) { multigrid_.apply(fine, reduced_.coarse_levels(), r_, s_); });
  ch09::for_parts(part, true, [&](int first, int last) { ch12::convert_rows(s_, s, first, last); });
  if (trial_team_ != 0) ch09::on_one_thread(true, [&] { ended_ = now_seconds(); });
}

}  // namespace fem::ch14
