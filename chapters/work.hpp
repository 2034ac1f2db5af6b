// The work of one step, phase by phase, as each chapter counts it from its own data: the
// course list's `work` hook (course.hpp), which the roofline lesson (apps/roofline) sets under
// the machine's roofs. A chapter counts its work in its own folder (chapters/NN_name/work.hpp
// declares `count_work(const <its stepper>&, const Scene&, const WorkCounts&)` in its
// namespace); a chapter that adds no part of its own is counted by the parts of the chapters
// it takes them from, and a student's variant, a copy of the folder, by its own copy.
//
// The model, kept simple so that a student can check it by hand (docs/roofline.md):
//  - bytes read and bytes written: every array a phase reads or writes, once per pass over it
//    (the compulsory traffic of the chapter's algorithm on its data structures). A write to a
//    line the pass did not read first costs that line's read too (write-allocate): the count
//    says so where it adds it. A write to a line the pass read first costs less (the line is
//    in the core already: its write-back only), and zeroing a matrix block by block has a roof
//    of its own: the count says which written bytes are zeroed.
//  - flops: the arithmetic the phase executes, a multiply or an add each (a multiply-add is
//    2), with the iterations it ran (CG, the rotations' Newton) as counted during the steps.
//  - working set: the distinct bytes one pass touches; the level of the cache hierarchy that
//    holds it gives the bandwidth. A phase made of kernels that run one after another on data
//    of different sizes (a solve: the PCG's passes, a V-cycle's levels) lists them as parts,
//    each with its own working set and so its own level: its whole working set in one level
//    would price the fine level's kernels, whose data fit an inner cache, at an outer one.
#pragma once

#include <functional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "common/scene.hpp"
#include "common/stepper.hpp"

namespace fem {

struct PhaseWork {
  std::string phase;  // a StepProfile phase: "forces", "dfdx", "compose", "constraints", "solve"
  double bytes_read = 0.0;       // arrays read (an array read and written back counts in both)
  double bytes_written = 0.0;    // arrays written
  double bytes_allocated = 0.0;  // of those, written to lines the pass did not read first:
                                 // the store reads each such line before it writes it
  double bytes_zeroed = 0.0;     // of those written, zeroed block by block (A's blocks'
                                 // setZero; not in bytes_allocated). The rest of the written
                                 // bytes go to lines the pass read first.
  double flops_double = 0.0;
  double flops_float = 0.0;  // float arithmetic, priced at the float peak
  double working_set = 0.0;  // bytes one pass over the phase's data touches
  // The kernels the phase is made of, each run as often as the phase runs it (the totals
  // above are their sums); empty: the phase is one kernel on its working set.
  std::vector<PhaseWork> parts;

  // The traffic: reads, writes and the line reads the allocating writes cost.
  double bytes() const { return bytes_read + bytes_written + bytes_allocated; }

  // `part` run `times` added to the totals and to the parts (a part's own parts in its place,
  // so that every part is one kernel); the working set is the caller's to say.
  void add_part(const PhaseWork& part, double times) {
    if (!part.parts.empty()) {
      for (const PhaseWork& p : part.parts) add_part(p, times);
      return;
    }
    PhaseWork run = part;
    run.bytes_read *= times;
    run.bytes_written *= times;
    run.bytes_allocated *= times;
    run.bytes_zeroed *= times;
    run.flops_double *= times;
    run.flops_float *= times;
    bytes_read += run.bytes_read;
    bytes_written += run.bytes_written;
    bytes_allocated += run.bytes_allocated;
    bytes_zeroed += run.bytes_zeroed;
    flops_double += run.flops_double;
    flops_float += run.flops_float;
    parts.push_back(std::move(run));
  }
};

// What a stepper ran, summed since it was made (its counters; zero where it has none): the
// roofline takes the difference over its measured steps.
struct ExecutedWork {
  double steps = 0.0;
  double rotations = 0.0;            // element rotations computed
  double rotation_iterations = 0.0;  // Newton iterations they took (fallbacks excluded)
  double rotation_fallbacks = 0.0;   // rotations Newton left to the SVD
  double team = 0.0;  // threads the last step ran on (an adaptive team may take one); 0: not said
  // (The synchronizations are counted per phase, in the StepProfile: PhaseCost.)

  ExecutedWork since(const ExecutedWork& before) const {
    return {steps - before.steps, rotations - before.rotations,
            rotation_iterations - before.rotation_iterations,
            rotation_fallbacks - before.rotation_fallbacks, team};
  }
};

// The counts a chapter's work depends on, per step: the solve's iterations and what the
// stepper's counters say it ran (ExecutedWork over the measured steps, divided by them).
struct WorkCounts {
  double cg_iterations = 0.0;
  ExecutedWork per_step;
};

// A kernel of one of a stepper's parts, timed alone by the roofline (the kernels-alone table):
// the part's own code on the part's own data, as the step runs it.
struct PartKernel {
  std::string name;           // e.g. "product q = A p"
  std::string part;           // the solve's part (PhaseWork::parts) it is, or with others makes up
  PhaseWork work;             // one call
  double calls = 0.0;         // per step
  std::function<void()> run;  // one call, by every thread of a team (or by one thread)
};

// The hook of CourseChapter: null for a chapter that counts nothing.
struct ChapterWork {
  std::vector<PhaseWork> (*count)(const Stepper&, const Scene&, const WorkCounts&) = nullptr;
  ExecutedWork (*executed)(const Stepper&) = nullptr;
  // The solve's kernels of the stepper's parts at `iterations` PCG iterations a step; they
  // run on the stepper's own data, so the stepper is the caller's, stepped a few times.
  std::vector<PartKernel> (*kernels)(Stepper&, const Scene&, double iterations) = nullptr;
};

// The hook of a chapter whose stepper is S: count_work (and executed_work, if any) for S,
// found by argument-dependent lookup (a chapter 01-07 stepper's own; from chapter 08 on the
// sum of the recipe's parts' counts, chapters/08_element_kernels/work.hpp). The course's list
// fills CourseChapter::work with it (chapters/course.hpp), for the steppers its `make` returns:
// those are S (inside on_one_thread's wrapper, which unwrapped removes), so the casts below cannot
// fail.
template <class S, class = void>
struct CountsWork : std::false_type {};
template <class S>
struct CountsWork<
    S, std::void_t<decltype(count_work(std::declval<const S&>(), std::declval<const Scene&>(),
                                       std::declval<const WorkCounts&>()))>> : std::true_type {};
template <class S, class = void>
struct CountsExecuted : std::false_type {};
template <class S>
struct CountsExecuted<S, std::void_t<decltype(executed_work(std::declval<const S&>()))>>
    : std::true_type {};

template <class S, class = void>
struct HasKernels : std::false_type {};
template <class S>
struct HasKernels<
    S, std::void_t<decltype(solve_kernels(std::declval<S&>(), std::declval<const Scene&>(), 1.0))>>
    : std::true_type {};

template <class S>
ChapterWork work_of() {
  ChapterWork work;
  if constexpr (CountsWork<S>::value)
    work.count = [](const Stepper& s, const Scene& scene, const WorkCounts& counts) {
      return count_work(static_cast<const S&>(unwrapped(s)), scene, counts);
    };
  if constexpr (CountsExecuted<S>::value)
    work.executed = [](const Stepper& s) {
      return executed_work(static_cast<const S&>(unwrapped(s)));
    };
  if constexpr (HasKernels<S>::value)
    work.kernels = [](Stepper& s, const Scene& scene, double iterations) {
      return solve_kernels(static_cast<S&>(unwrapped(s)), scene, iterations);
    };
  return work;
}

}  // namespace fem
