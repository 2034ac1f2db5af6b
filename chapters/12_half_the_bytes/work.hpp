// This chapter's parts' work (chapters/08_element_kernels/work.hpp: counted part by part): the
// batched pass computes the fused pass's terms, a batch at a time; the V-cycle's levels in
// float, its arithmetic in float or in double as the part says.
#pragma once

#include <algorithm>
#include <memory>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "chapters/08_element_kernels/work.hpp"
#include "chapters/09_threads/work.hpp"
#include "chapters/10_multigrid/work.hpp"
#include "chapters/12_half_the_bytes/parts.hpp"
#include "chapters/12_half_the_bytes/reduced_kernels.hpp"

namespace fem::ch12 {

ch08::ElementWork element_work(const BatchedElementPass& part, const ch08::WorkInput& in);
// The batched pass's counters: rotations, Newton's iterations (every lane of a batch runs the
// batch's), fallbacks.
ExecutedWork element_counters(const BatchedElementPass& part, double elements);
// The same of any part that runs the batches (chapter 14's too).
ExecutedWork batch_counters(const BatchedElements& batched, double elements);

template <class Real>
ch08::PreconditionerWork preconditioner_work(const ReducedMultigrid<Real>& part,
                                             const ch08::WorkInput& in) {
  return ch10::multigrid_work(part.multigrid(), in, sizeof(float), std::is_same_v<Real, float>);
}

// The fine level's smoothing step of the float V-cycle alone (chapter 10's polynomial step, a
// step after the first: it reads x, b and the direction and writes y and the direction),
// counted as chapter 10 counts one of the level's products; smoother_products of them per
// V-cycle. None where the hierarchy has one level.
template <class Real>
std::vector<PartKernel> smoothing_kernels(ReducedVCycle<Real>& cycle,
                                          const ch10::Multigrid& multigrid,
                                          const ch08::KernelInput& in) {
  if (multigrid.levels() < 2) return {};
  const std::vector<ch10::LevelSize> levels = ch10::multigrid_levels(multigrid);
  PhaseWork one =
      ch10::v_cycle_work({levels.front()}, 1, sizeof(float), std::is_same_v<Real, float>)
          .parts.front();
  const std::string part = one.phase;
  one.phase = "smoothing step";
  auto& fine = cycle.fine_level();
  const int step = std::min(1, ch10::smoothing_steps(fine) - 1);
  return {ch09::part_kernel(
      std::is_same_v<Real, float> ? "fine smoothing step (float)"
                                  : "fine smoothing step (double on float)",
      part, one, in.passes * ch10::smoother_products(multigrid), [&fine, step] {
        ch09::for_parts(source_level(fine).rows.part, true, [&](int first, int last) {
          ch10::smooth(fine, step, first, last, fine.vectors.b, &fine.vectors.x, fine.vectors.y,
                       true);
        });
      })};
}

// The part of `work` named `phase` (one of chapter 10's v_cycle_work parts).
inline PhaseWork part_named(const PhaseWork& work, const std::string& phase) {
  for (const PhaseWork& p : work.parts)
    if (p.phase == phase) return p;
  throw std::logic_error("no part named " + phase);
}

// A loop over `part`'s rows as v_cycle runs it on `level`: shared by the team, or on one
// thread where the level is small (serial). Called by every thread of a team.
template <class Level, class Loop>
void as_the_cycle_runs(const Level& level, const std::vector<int>& part, Loop loop) {
  if (source_level(level).rows.serial)
    ch09::on_one_thread(true, [&] { ch09::for_parts(part, false, loop); });
  else
    ch09::for_parts(part, true, loop);
}

// The restriction to `below` and the prolongation from it of `level` (level `k`), alone.
template <class Level, class Coarse>
void add_transfer_kernels(Level& level, Coarse& below, int k, const PhaseWork& one,
                          const ch08::KernelInput& in, std::vector<PartKernel>& kernels) {
  const std::string name = "level " + std::to_string(k) + " ";
  for (const std::string transfer : {"restriction", "prolongation"}) {
    const auto work = part_named(one, name + transfer);
    const bool restriction = transfer == "restriction";
    kernels.push_back(ch09::part_kernel(
        name + transfer, work.phase, work, in.passes, [&level, &below, restriction] {
          if (restriction)
            as_the_cycle_runs(level, source_level(below).rows.part, [&](int first, int last) {
              restrict_rows(level, below, first, last);
            });
          else
            as_the_cycle_runs(level, source_level(level).rows.part, [&](int first, int last) {
              prolong_rows(level, below, first, last, level.vectors.x);
            });
        }));
  }
}

// Coarse level `k` (k >= 1) alone: its smoothing step and its transfers, or the coarsest solve.
template <class Coarse>
void add_coarse_kernels(std::vector<Coarse>& coarse, int k, const PhaseWork& one, double products,
                        const ch08::KernelInput& in, std::vector<PartKernel>& kernels) {
  Coarse& level = coarse[k - 1];
  const std::string name = "level " + std::to_string(k) + " ";
  if (source_level(level).coarsest) {
    const auto work = part_named(one, name + "coarsest solve");
    kernels.push_back(
        ch09::part_kernel(name + "coarsest solve", work.phase, work, in.passes, [&level] {
          ch09::on_one_thread(true,
                              [&] { solve_coarsest(level, level.vectors.b, level.vectors.x); });
        }));
    return;
  }
  const auto work = part_named(one, name + "smoothing and residual");
  const int step = std::min(1, smoothing_steps(level) - 1);
  kernels.push_back(ch09::part_kernel(
      name + "smoothing step", work.phase, work, in.passes * products, [&level, step] {
        as_the_cycle_runs(level, source_level(level).rows.part, [&](int first, int last) {
          smooth(level, step, first, last, level.vectors.b, &level.vectors.x, level.vectors.y,
                 true);
        });
      }));
  add_transfer_kernels(level, coarse[k], k, one, in, kernels);
}

// The V-cycle's kernels below its fine smoothing step, each alone and run as the cycle runs it
// (v_cycle.hpp), each counted as chapter 10 counts its part (v_cycle_work): the fine level's
// transfers, every coarse level's smoothing step and transfers, the coarsest solve. With them
// the roofline's "between the kernels" holds only what lies between the kernels.
template <class Fine, class Coarse>
std::vector<PartKernel> below_fine_kernels(Fine& fine, std::vector<Coarse>& coarse,
                                           const ch10::Multigrid& multigrid, bool float_arithmetic,
                                           const ch08::KernelInput& in) {
  std::vector<PartKernel> kernels;
  if (multigrid.levels() < 2) return kernels;
  const PhaseWork one =
      ch10::v_cycle_work(ch10::multigrid_levels(multigrid), 1, sizeof(float), float_arithmetic);
  add_transfer_kernels(fine, coarse.front(), 0, one, in, kernels);
  const double products = ch10::smoother_products(multigrid);
  for (int k = 1; k < multigrid.levels(); ++k)
    add_coarse_kernels(coarse, k, one, products, in, kernels);
  return kernels;
}

// The float V-cycle's entry and exit alone, r into float and s back into double on the fine
// level's rows (convert_rows, as apply runs them), counted as chapter 01 counts a
// preconditioner's own (pcg_work: r read, s written).
inline PartKernel entry_and_exit_kernel(const std::vector<int>& part, const ch08::KernelInput& in) {
  struct Vectors {
    Eigen::VectorXd r, s;
    Eigen::VectorXf r_float, s_float;
  };
  auto v = std::make_shared<Vectors>();
  const Eigen::Index n = 3 * Eigen::Index(part.back());
  v->r = v->s = Eigen::VectorXd::LinSpaced(n, 1e-3, 1.0);
  v->r_float = v->s_float = Eigen::VectorXf::LinSpaced(n, 1e-3f, 1.0f);
  const double vector = in.m.vector_bytes;
  const PhaseWork work =
      ch01::phase_work("preconditioner", vector, vector, vector, 0.0, 2 * vector);
  return ch09::part_kernel(
      "r into float, s back into double", "preconditioner", work, in.passes, [v, part] {
        ch09::for_parts(part, true,
                        [&](int first, int last) { convert_rows(v->r, v->r_float, first, last); });
        ch09::for_parts(part, true,
                        [&](int first, int last) { convert_rows(v->s_float, v->s, first, last); });
      });
}

template <class Real>
std::vector<PartKernel> preconditioner_kernels(ReducedMultigrid<Real>& part,
                                               const ch08::KernelInput& in) {
  std::vector<PartKernel> kernels = smoothing_kernels(part.v_cycle(), part.multigrid(), in);
  for (PartKernel& k :
       below_fine_kernels(part.v_cycle().fine_level(), part.v_cycle().coarse_levels(),
                          part.multigrid(), std::is_same_v<Real, float>, in))
    kernels.push_back(std::move(k));
  if (std::is_same_v<Real, float> && part.multigrid().levels() > 1)
    kernels.push_back(
        entry_and_exit_kernel(source_level(part.v_cycle().fine_level()).rows.part, in));
  return kernels;
}

}  // namespace fem::ch12
