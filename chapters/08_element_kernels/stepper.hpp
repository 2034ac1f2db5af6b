// Chapter 08: the element loop at the speed of its arithmetic. Until now every chapter
// called common/'s element kernels: a JacobiSVD per element for the rotation, a stored
// 12x12 K0 per element (1.3 KB of rest data), df/dx built and then composed into A. This
// chapter makes the element work its own: the rotation by a Newton iteration warm-started
// from the last steps' rotations, the blocks of -df/dx in closed form from the shape gradients,
// and one pass over the elements that writes forces and blocks straight into b and A.
//
// And it writes the step once, over a recipe of named parts (step.hpp), each part bringing what
// its role needs (contract.hpp), so that every later chapter changes the step by naming other
// parts: this recipe is the first. Each part's kName and kChapter say what it is and where it is
// taught; `out << stepper` prints them.
#pragma once

#include "chapters/08_element_kernels/serial_parts.hpp"
#include "chapters/08_element_kernels/step.hpp"

namespace fem::ch08 {

struct ElementKernels {
  using Order = ch08::MeshOrder;
  using Team = ch08::OneThread;
  using Elements = ch08::SerialElements;
  using Guess = ch08::WarmStart;
  using Product = ch08::AssembledProduct;
  using Preconditioner = ch08::BlockJacobi;
  using Solver = ch08::SerialPcg;
};

using ElementKernelsStepper = StepOf<ElementKernels>;

}  // namespace fem::ch08
