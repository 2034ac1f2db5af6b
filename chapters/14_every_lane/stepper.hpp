// Chapter 14: every vector lane busy. Chapter 12's step with the V-cycle's finest level in
// pair lanes (lane_v_cycle.hpp): two 3x3 blocks of a row side by side in one register, where
// chapter 12 loads one block's column into four of a register's eight or sixteen lanes; and
// chapter 12's element batches scattered into A a register a block, fetched ahead where A is
// larger than the last cache (lane_scatter.hpp); and the solve's product q = A p in double
// pair lanes (lane_product.hpp), the solver unchanged: the product is a part of its own.
#pragma once

// The recipe it builds on, and the files of the parts it adds.
#include "chapters/12_half_the_bytes/stepper.hpp"
#include "chapters/14_every_lane/lane_product.hpp"
#include "chapters/14_every_lane/parts.hpp"

namespace fem::ch14 {

struct EveryLane {
  using BuildsOn = ch12::HalfTheBytes;
  using Order = ch11::RenumberedNodes;
  using Team = ch09::TeamOfThreads;
  using Elements = ch14::LaneScatterPass;
  using Guess = ch10::Extrapolation;
  using Product = ch14::LaneProduct;
  using Preconditioner = ch14::LaneMultigrid;
  using Solver = ch09::ParallelPcgSolver;
};

using EveryLaneStepper = ch08::StepOf<EveryLane>;

}  // namespace fem::ch14
