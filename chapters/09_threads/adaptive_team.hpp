// How many threads the next step uses: the count the program was given, or one thread when
// that has lately been faster.
//
// Why the count may change from one step to the next: every sum of the chapter runs over
// fixed chunks in a fixed order, so the state does not depend on the thread count (the tests
// check it to the bit), and the count becomes a free choice made at run time.
//
// Why it has to: the threads of a step meet at hundreds of barriers (three per PCG iteration),
// and a barrier waits for the slowest thread. While the machine is free, that costs a
// microsecond. When another process keeps a core busy, the operating system runs one of the
// two threads only every other time slice (milliseconds), every barrier waits for it, and
// libgomp's default wait policy keeps the waiting thread spinning on its core meanwhile: two
// threads then take several times one thread's time (chapter 09's README has the numbers).
//
// So the team measures itself: the median time of the last steps with the team in use, and
// every `period` steps one probe step with the other team (one thread, or all of them). A probe
// clearly faster (by kGain) switches; a probe that is not doubles the period (up to kMaxPeriod),
// so a machine that stays free pays one slower step in 256. When the team's usual time grows
// by half (the machine got busy), the next step is a probe.
#pragma once

namespace fem::ch09 {

class AdaptiveTeam {
 public:
  // The team of the next step, given the program's thread count (OpenMP's): that count
  // itself when it was asked for (common/threads.hpp's thread_count_asked).
  int next(int given);
  // The time of the step that ran with next()'s team.
  void record(double seconds);
  // Off: every step uses the program's count (tests that compare thread counts).
  void set_enabled(bool enabled) { enabled_ = enabled; }
  bool enabled() const { return enabled_; }
  int switches() const { return switches_; }
  int team() const { return team_; }  // of the last step

 private:
  static constexpr int kWindow = 3, kFirstPeriod = 8, kMaxPeriod = 256;
  static constexpr double kGain = 0.8;    // a probe must take at most 0.8 of the usual time
  static constexpr double kChange = 1.5;  // a usual time 1.5 times up or down: probe now
  double usual() const;                   // median of the window

  bool enabled_ = true;
  int given_ = 0;         // the program's count when the window was filled
  int current_ = 0;       // the team in use
  int team_ = 0;          // the team of the step being run
  bool chosen_ = false;   // this step's team was chosen (enabled, more than one thread given)
  bool probing_ = false;  // this step is a probe of the other team
  int period_ = kFirstPeriod, until_probe_ = kFirstPeriod;
  double window_[kWindow] = {};
  double reference_ = 0.0;  // the usual time at the last decision
  int recorded_ = 0;        // steps in the window since the last switch
  int switches_ = 0;
};

}  // namespace fem::ch09
