// Chapter 10: the V-cycle, written once for any level's numbers. A level type brings its own
// kernels, found by argument-dependent lookup as AMGCL's backends bring theirs:
//   source_level(level) (its row blocks, and whether it is the coarsest), smoothing_steps(level),
//   smooth(level, k, first, last, b, in, out, forward), residual(level, first, last, b, x),
//   restrict_rows(level, coarse, first, last), prolong_rows(level, coarse, first, last, x),
//   solve_coarsest(level, b, out),
// and its vectors in level.vectors (WorkVectors: b, x, y, residual). This chapter's levels
// (level.hpp) hold doubles; a level that stores its numbers in float and computes in float or
// double runs the same cycle.
//
// Every loop is shared out over the level's fixed row blocks (ch09::for_parts), every row
// written by one thread, every sum in a fixed order: the result is the same to the last bit
// for any thread count.
#pragma once

#include <cstddef>
#include <vector>

#include "chapters/09_threads/parallel.hpp"

namespace fem::ch10 {

// One V-cycle on `level` from a zero guess: b -> out (out may be the level's x); coarse[next]
// is the level below it. A small level (serial) and those below run on one thread; the
// coarsest is a direct solve. Called by every thread of a team (collective), or by one.
template <class Level, class Coarse, class Vector>
void v_cycle(Level& level, std::vector<Coarse>& coarse, std::size_t next, const Vector& b,
             Vector& out, bool collective) {
  const std::vector<int>& part = source_level(level).rows.part;
  if (collective && source_level(level).rows.serial) {
    ch09::on_one_thread(true, [&] { v_cycle(level, coarse, next, b, out, false); });
    return;
  }
  if (source_level(level).coarsest) {
    ch09::on_one_thread(collective, [&] { solve_coarsest(level, b, out); });
    return;
  }
  const int steps = smoothing_steps(level);
  // Pre-smoothing from zero, ping-ponging between x and y: a step reads the last one's
  // result on every row and writes its own rows of the other vector.
  const Vector* current = nullptr;
  for (int k = 0; k < steps; ++k) {
    Vector& target = k % 2 == 0 ? level.vectors.x : level.vectors.y;
    ch09::for_parts(part, collective, [&](int first, int last) {
      smooth(level, k, first, last, b, current, target, true);
    });
    current = &target;
  }
  ch09::for_parts(part, collective,
                  [&](int first, int last) { residual(level, first, last, b, *current); });
  // The coarse correction: the residual restricted, the next level's cycle, and its
  // correction prolonged, y = x + P x_c.
  Coarse& below = coarse[next];
  ch09::for_parts(source_level(below).rows.part, collective,
                  [&](int first, int last) { restrict_rows(level, below, first, last); });
  v_cycle(below, coarse, next + 1, below.vectors.b, below.vectors.x, collective);
  ch09::for_parts(part, collective,
                  [&](int first, int last) { prolong_rows(level, below, first, last, *current); });
  // Post-smoothing from y, the adjoint of the pre-smoothing, ending in out.
  current = &level.vectors.y;
  for (int k = 0; k < steps; ++k) {
    Vector& target = (steps - k) % 2 == 1 ? out : level.vectors.residual;
    ch09::for_parts(part, collective, [&](int first, int last) {
      smooth(level, k, first, last, b, current, target, false);
    });
    current = &target;
  }
}

}  // namespace fem::ch10
