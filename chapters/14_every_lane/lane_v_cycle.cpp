#include "chapters/14_every_lane/lane_v_cycle.hpp"

#include <algorithm>
#include <chrono>
#include <limits>

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

// The wall time of `sweeps` smoothing steps over the level's rows on this team, after one
// untimed to bring its data to where the V-cycle finds them; step 1 from x, as the V-cycle
// runs most. Every thread returns the time one thread took from barrier to barrier, through
// `seconds`, which the team shares (a member of the cycle: two bodies' teams may time at
// once). The level's direction and y are overwritten (the V-cycle's first step writes both
// afresh).
template <class Lanes>
double smoothing_seconds(Lanes& fine, int sweeps, double& seconds) {
  auto& v = fine.vectors;
  const int step = std::min(1, ch10::smoothing_steps(fine) - 1);
  const auto sweep = [&] {
    ch09::for_parts(source_level(fine).rows.part, true, [&](int first, int last) {
      smooth_rows(fine, step, first, last, v.b, &v.x, v.y);
    });
  };
  sweep();
  const auto start = std::chrono::steady_clock::now();
  for (int k = 0; k < sweeps; ++k) sweep();
  ch09::on_one_thread(true, [&] {
    seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  });
  return seconds;
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

// The layouts timed in turn, kRounds rounds of kSweeps sweeps each, and each layout's best round
// kept: a single timing of each (three sweeps, first) picked on beam_50k the layout the lesson's
// smoothing kernel found slower, because a sweep there takes a millisecond and a machine's hiccup
// is as long. Alternating spreads a drift of the machine over both; the best round is the one
// least disturbed. It has not settled the question: where the two are within a few percent (one
// thread) the choice follows the noise, and at two threads the faster one swapped between
// sittings (the README's measured effect). On the plate the whole takes a millisecond, on an
// 80,000-node beam about a tenth of one step, once per team size.
Layout LaneVCycle::time_layouts() {
  constexpr int kRounds = 5, kSweeps = 2;
  fill(padded_);
  fill(packed_);
  double padded = std::numeric_limits<double>::infinity(), packed = padded;
  for (int round = 0; round < kRounds; ++round) {
    padded = std::min(padded, smoothing_seconds(padded_, kSweeps, timed_seconds_));
    packed = std::min(packed, smoothing_seconds(packed_, kSweeps, timed_seconds_));
  }
  return packed < padded ? Layout::packed : Layout::padded;
}

void LaneVCycle::prepare(const ch07::BlockSparseMatrix& A) {
  reduced_.prepare(A);
  if (!lanes_) return;
  const int team = std::clamp(team_size(), 1, kTeams);
  Layout layout = forced_.value_or(Layout::padded);
  const bool timed = !forced_ && measured_[team] < 0;
  if (timed) {
    layout = time_layouts();
    ch09::on_one_thread(true, [&] { measured_[team] = static_cast<signed char>(layout); });
  } else if (!forced_) {
    layout = Layout(measured_[team]);
  }
  ch09::on_one_thread(true, [&] { current_ = layout; });
  if (timed) return;  // both filled
  if (layout == Layout::padded)
    fill(padded_);
  else
    fill(packed_);
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
