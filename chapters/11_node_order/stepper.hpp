// Chapter 11: the order of memory. Chapter 10's step, unchanged, on the mesh renumbered once
// at construction (reverse Cuthill-McKee by default, node_order.hpp), with the elements
// sorted by their nodes in the new order (renumbered_nodes.hpp). The caller keeps the mesh's
// numbering: the state and the interaction forces are mapped in and out at the step's
// boundary.
#pragma once

// The recipe it builds on, and the files of the parts it adds.
#include "chapters/10_multigrid/stepper.hpp"
#include "chapters/11_node_order/renumbered_nodes.hpp"

namespace fem::ch11 {

struct NodeOrderRecipe {
  using BuildsOn = ch10::MultigridRecipe;
  using Order = ch11::RenumberedNodes;
  using Team = ch09::TeamOfThreads;
  using Elements = ch09::ThreadedElements;
  using Guess = ch10::Extrapolation;
  using Product = ch08::AssembledProduct;
  using Preconditioner = ch10::MultigridPreconditioner;
  using Solver = ch09::ParallelPcgSolver;
};

using NodeOrderStepper = ch08::StepOf<NodeOrderRecipe>;

}  // namespace fem::ch11
