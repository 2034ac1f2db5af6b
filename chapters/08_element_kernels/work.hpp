// This chapter's work per phase (chapters/work.hpp: the model), counted part by part: a step
// of parts (step.hpp) is counted as the sum of what its parts count, each part's count in the
// chapter that teaches it (that chapter's work.hpp, found by argument-dependent lookup):
//   element_work(elements, in)            the phases forces and compose
//   product_work(product, A)              one q = A p, and its set-up per solve
//   preconditioner_work(preconditioner, in) one application, and its set-up per solve
//   solver_work(solver, in, preconditioner) the solve phase
//   element_counters(elements, elements_count), team_size(team): what the parts ran
// So a chapter that adds a part adds its count, and a chapter is counted as itself.
#pragma once

#include <vector>

#include "chapters/01_naive/work.hpp"
#include "chapters/07_block_sparse/work.hpp"
#include "chapters/08_element_kernels/serial_parts.hpp"
#include "chapters/08_element_kernels/step.hpp"
#include "chapters/work.hpp"

namespace fem::ch08 {

// A product part: one q = A p (the matrix it streams and its flops), and what its set-up per
// solve reads and writes (a copy of A into another layout).
struct ProductWork {
  double matrix_bytes = 0.0, flops = 0.0;
  double prepare_read = 0.0, prepare_written = 0.0;
};

// What every part's count reads.
struct WorkInput {
  const ch01::MeshSizes& m;
  const BlockSparseMatrix& A;
  const Scene& scene;
  const WorkCounts& counts;
  ProductWork product;  // the recipe's product's (product_work)
};

// An element part's two phases.
struct ElementWork {
  PhaseWork forces, compose;
};
// A preconditioner part: one application (a V-cycle keeps its kernels as parts), and what its
// set-up per solve reads and writes (fresh lines).
struct PreconditionerWork {
  PhaseWork apply;
  double prepare_read = 0.0, prepare_written = 0.0;
};

// The fused pass and what is left of the composition: the counts of every element part from
// chapter 08 on, which compute the same terms (one element or a batch of them at a time).
ElementWork fused_pass_work(const WorkInput& in);
// A PCG's own kernels with `preconditioner`, and its set-up as a part of the solve.
PhaseWork pcg_solve_work(const WorkInput& in, const PreconditionerWork& preconditioner);
// The solve of a PCG whose own kernels (product and updates, per iteration) count `own`.
PhaseWork solve_work(const WorkInput& in, const PhaseWork& own,
                     const PreconditionerWork& preconditioner);

ElementWork element_work(const SerialElements& part, const WorkInput& in);
ProductWork product_work(const AssembledProduct& part, const BlockSparseMatrix& A);
PreconditionerWork preconditioner_work(const BlockJacobi& part, const WorkInput& in);
PhaseWork solver_work(const SerialPcg& part, const WorkInput& in,
                      const PreconditionerWork& preconditioner);
ExecutedWork element_counters(const SerialElements& part, double elements);
inline double team_size(const OneThread&) { return 0.0; }  // not said: one thread

// Block Jacobi's per solve: each diagonal block read and its inverse written.
PreconditionerWork block_jacobi_work(const WorkInput& in);
// The fused element loop's counters: steps, rotations, Newton's iterations and fallbacks.
ExecutedWork fused_counters(const FusedElements& elements);

template <class Recipe>
std::vector<PhaseWork> count_work(const StepOf<Recipe>& stepper, const Scene& scene,
                                  const WorkCounts& counts) {
  const ch01::MeshSizes m = ch01::mesh_sizes(scene);
  const WorkInput in{m, stepper.system_matrix(), scene, counts,
                     product_work(stepper.product(), stepper.system_matrix())};
  const ElementWork elements = element_work(stepper.elements(), in);
  const PreconditionerWork preconditioner = preconditioner_work(stepper.preconditioner(), in);
  return {elements.forces, elements.compose,
          ch07::block_constraints(m, stepper.system_matrix(), scene),
          solver_work(stepper.solver(), in, preconditioner)};
}

// What a part's kernels alone are built from: `passes` PCG passes a step (iterations + 1), and
// the recipe's product, which the solver's kernels run.
struct KernelInput {
  const ch01::MeshSizes& m;
  const BlockSparseMatrix& A;
  const Scene& scene;
  double passes;
  ProductPart& product;
  ProductWork product_work;
};
// Chapter 08's solve runs on one thread: the roofline's kernels alone start with chapter 09's.
inline std::vector<PartKernel> solver_kernels(SerialPcg&, const KernelInput&) { return {}; }
inline std::vector<PartKernel> preconditioner_kernels(BlockJacobi&, const KernelInput&) {
  return {};
}

// The solve's kernels of a step of parts, each timed through its part: the solver's
// (solver_kernels) and the preconditioner's (preconditioner_kernels), found by argument-
// dependent lookup in the parts' chapters.
template <class Recipe>
std::vector<PartKernel> solve_kernels(StepOf<Recipe>& stepper, const Scene& scene,
                                      double iterations) {
  const ch01::MeshSizes m = ch01::mesh_sizes(scene);
  const KernelInput in{m,
                       stepper.system_matrix(),
                       scene,
                       iterations + 1.0,
                       stepper.product(),
                       product_work(stepper.product(), stepper.system_matrix())};
  std::vector<PartKernel> kernels = solver_kernels(stepper.solver(), in);
  for (PartKernel& k : preconditioner_kernels(stepper.preconditioner(), in))
    kernels.push_back(std::move(k));
  if (kernels.empty()) return kernels;
  // The solve's set-up, once a step: the product's and the preconditioner's numbers from this
  // step's A (copies into their layouts, a multigrid's factorize), as the solver's team runs it.
  PartKernel set_up;
  set_up.name = "prepare: the product's and the preconditioner's numbers from A";
  set_up.part = "prepare";
  const std::vector<PhaseWork> counted = count_work(stepper, scene, WorkCounts{iterations, {}});
  for (const PhaseWork& p : counted.back().parts)  // the solve's parts (a temporary's would dangle)
    if (p.phase == set_up.part) set_up.work = p;
  set_up.calls = 1.0;
  set_up.run = [&stepper] {
    stepper.product().prepare(stepper.system_matrix());
    stepper.preconditioner().prepare(stepper.system_matrix());
  };
  kernels.push_back(std::move(set_up));
  return kernels;
}

template <class Recipe>
ExecutedWork executed_work(const StepOf<Recipe>& stepper) {
  ExecutedWork e = element_counters(stepper.elements(), double(stepper.model().tets.size()));
  e.team = team_size(stepper.team());
  return e;
}

// Flops of one element of the fused pass besides its rotation, term by term from the
// kernels' formulas (element_kernels.cpp), and of the rotation: per Newton iteration and
// once per rotation Newton found (its normalization and its matrix).
double fused_element_flops();
double newton_iteration_flops();
double newton_finish_flops();
// The rotations' flops of one step: from the iterations counted during the steps
// (counts.per_step), or at least one iteration per element where nothing was counted.
double rotation_flops(const WorkCounts& counts, double elements);

}  // namespace fem::ch08
