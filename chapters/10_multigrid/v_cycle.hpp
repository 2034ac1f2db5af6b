// Chapter 10: the V-cycle, written once for any level's numbers. A level type brings its own
// kernels, found by argument-dependent lookup as AMGCL's backends bring theirs, and checked by
// check_level_kernels below, which names a missing one:
//   source_level(level) (its row blocks, and whether it is the coarsest), smoothing_steps(level),
//   smooth(level, k, first, last, b, in, out, forward), residual(level, first, last, b, x),
//   restrict_rows(level, coarse, first, last), prolong_rows(level, coarse, first, last, x),
//   solve_coarsest(level, b, out),
// and its vectors in level.vectors (WorkVectors: b, x, y, residual). This chapter's levels
// (level.hpp) hold doubles; a level that stores its numbers in float and computes in float or
// double runs the same cycle, and by deriving from PolynomialLevel (smoothers.hpp) takes this
// chapter's polynomial smoothing steps and residual on its own products.
//
// Every loop is shared out over the level's fixed row blocks (ch09::for_parts), every row
// written by one thread, every sum in a fixed order: the result is the same to the last bit
// for any thread count. for_levels_from is the hierarchy's one walk over its levels (the
// refresh rule's "the levels below too" and the serial rule), for factorize and for any copy
// of the levels that holds other numbers.
#pragma once

#include <cstddef>
#include <type_traits>
#include <utility>
#include <vector>

#include "chapters/09_threads/parallel.hpp"

namespace fem::ch10 {

// ---- the level interface: one probe per kernel ------------------------------------------------

namespace level_interface {

template <class L, class = void>
struct has_source_level : std::false_type {};
template <class L>
struct has_source_level<L, std::void_t<decltype(source_level(std::declval<const L&>()).rows.part),
                                       decltype(source_level(std::declval<const L&>()).coarsest)>>
    : std::true_type {};

template <class L, class = void>
struct has_smoothing_steps : std::false_type {};
template <class L>
struct has_smoothing_steps<L, std::void_t<decltype(smoothing_steps(std::declval<L&>()))>>
    : std::true_type {};

template <class L, class V, class = void>
struct has_smooth : std::false_type {};
template <class L, class V>
struct has_smooth<L, V,
                  std::void_t<decltype(smooth(std::declval<L&>(), 0, 0, 0, std::declval<const V&>(),
                                              std::declval<const V*>(), std::declval<V&>(), true))>>
    : std::true_type {};

template <class L, class V, class = void>
struct has_residual : std::false_type {};
template <class L, class V>
struct has_residual<
    L, V,
    std::void_t<decltype(residual(std::declval<L&>(), 0, 0, std::declval<const V&>(),
                                  std::declval<const V&>()))>> : std::true_type {};

template <class L, class C, class = void>
struct has_restrict_rows : std::false_type {};
template <class L, class C>
struct has_restrict_rows<
    L, C, std::void_t<decltype(restrict_rows(std::declval<L&>(), std::declval<C&>(), 0, 0))>>
    : std::true_type {};

template <class L, class C, class V, class = void>
struct has_prolong_rows : std::false_type {};
template <class L, class C, class V>
struct has_prolong_rows<L, C, V,
                        std::void_t<decltype(prolong_rows(std::declval<L&>(), std::declval<C&>(), 0,
                                                          0, std::declval<const V&>()))>>
    : std::true_type {};

template <class L, class V, class = void>
struct has_solve_coarsest : std::false_type {};
template <class L, class V>
struct has_solve_coarsest<L, V,
                          std::void_t<decltype(solve_coarsest(
                              std::declval<L&>(), std::declval<const V&>(), std::declval<V&>()))>>
    : std::true_type {};

template <class L, class V, class = void>
struct has_vectors : std::false_type {};
template <class L, class V>
struct has_vectors<
    L, V,
    std::enable_if_t<std::is_same_v<decltype(std::declval<L&>().vectors.b), V> &&
                     std::is_same_v<decltype(std::declval<L&>().vectors.x), V> &&
                     std::is_same_v<decltype(std::declval<L&>().vectors.y), V> &&
                     std::is_same_v<decltype(std::declval<L&>().vectors.residual), V>>>
    : std::true_type {};

}  // namespace level_interface

// Whether `Level`, with `Coarse` below it and vectors of type `Vector`, brings every kernel
// v_cycle calls. In a static_assert, a missing kernel is named by its own message.
template <class Level, class Coarse, class Vector>
constexpr bool check_level_kernels() {
  using namespace level_interface;
  static_assert(has_source_level<Level>::value,
                "V-cycle level: no source_level(level) returning the ch10::Level it reads");
  static_assert(has_smoothing_steps<Level>::value, "V-cycle level: no smoothing_steps(level)");
  static_assert(has_smooth<Level, Vector>::value,
                "V-cycle level: no smooth(level, k, first, last, b, in, out, forward)");
  static_assert(has_residual<Level, Vector>::value,
                "V-cycle level: no residual(level, first, last, b, x)");
  static_assert(has_restrict_rows<Level, Coarse>::value,
                "V-cycle level: no restrict_rows(level, coarse, first, last)");
  static_assert(has_prolong_rows<Level, Coarse, Vector>::value,
                "V-cycle level: no prolong_rows(level, coarse, first, last, x)");
  static_assert(has_solve_coarsest<Level, Vector>::value,
                "V-cycle level: no solve_coarsest(level, b, out)");
  static_assert(
      has_vectors<Level, Vector>::value,
      "V-cycle level: level.vectors.{b, x, y, residual} are not of the cycle's vector type");
  return true;
}

// ---- the hierarchy's walk over its levels --------------------------------------------------

// work(level, next, collective) on `level` and, when `below`, on every level below it
// (coarse[next] is the one under `level`). A small level (serial) and those below it run on one
// thread: there a barrier costs more than the work it shares out. Called by every thread of a
// team (collective), or by one.
template <class Level, class Coarse, class Work>
void for_levels_from(Level& level, std::vector<Coarse>& coarse, std::size_t next, bool collective,
                     bool below, Work& work) {
  if (collective && source_level(level).rows.serial) {
    ch09::on_one_thread(true, [&] { for_levels_from(level, coarse, next, false, below, work); });
    return;
  }
  work(level, next, collective);
  if (below && !source_level(level).coarsest)
    for_levels_from(coarse[next], coarse, next + 1, collective, below, work);
}

// ---- the V-cycle -------------------------------------------------------------------------------

// One V-cycle on `level` from a zero guess: b -> out (out may be the level's x); coarse[next]
// is the level below it. A small level (serial) and those below run on one thread; the
// coarsest is a direct solve. Called by every thread of a team (collective), or by one.
template <class Level, class Coarse, class Vector>
void v_cycle(Level& level, std::vector<Coarse>& coarse, std::size_t next, const Vector& b,
             Vector& out, bool collective) {
  static_assert(check_level_kernels<Level, Coarse, Vector>());
  static_assert(check_level_kernels<Coarse, Coarse, Vector>());
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
