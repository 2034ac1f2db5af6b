#include "chapters/registry.hpp"

#include <stdexcept>

#include "chapters/01_naive/stepper.hpp"
#include "chapters/02_noalias/stepper.hpp"
#include "chapters/03_indexed_access/stepper.hpp"
#include "chapters/04_system_composition/stepper.hpp"
#include "chapters/05_inplace_constraints/stepper.hpp"
#include "chapters/06_custom_pcg/stepper.hpp"
#include "chapters/07_block_sparse/stepper.hpp"
#include "chapters/08_element_kernels/stepper.hpp"
#include "chapters/09_threads/stepper.hpp"

namespace fem {
namespace {

template <class ChapterStepper>
ChapterInfo chapter(std::string id, std::string title) {
  return {std::move(id), std::move(title), [](const Scene& scene, const SolverSettings& s) {
            return std::unique_ptr<Stepper>(std::make_unique<ChapterStepper>(scene, s));
          }};
}

}  // namespace

const std::vector<ChapterInfo>& chapters() {
  static const std::vector<ChapterInfo> list = {
      chapter<ch01::NaiveStepper>("01_naive", "Eigen as the documentation suggests"),
      chapter<ch02::NoAliasStepper>("02_noalias", "no hidden temporaries in assignments"),
      chapter<ch03::IndexedAccessStepper>("03_indexed_access",
                                          "df/dx through a table of value offsets"),
      chapter<ch04::SystemCompositionStepper>("04_system_composition",
                                              "A and b in one pass over shared value arrays"),
      chapter<ch05::InplaceConstraintsStepper>("05_inplace_constraints",
                                               "S A S^T applied in place, no S"),
      chapter<ch06::CustomPcgStepper>("06_custom_pcg", "our own PCG: warm start, no allocations"),
      chapter<ch07::BlockSparseStepper>("07_block_sparse", "3x3 block sparse matrix, block Jacobi"),
      chapter<ch08::ElementKernelsStepper>(
          "08_element_kernels", "warm-started rotations, closed-form blocks, one fused pass"),
      chapter<ch09::ThreadsStepper>("09_threads", "every core, the same answer for any thread count"),
  };
  return list;
}

const ChapterInfo& find_chapter(const std::string& name) {
  std::string known;
  for (const auto& c : chapters()) {
    const std::string number = c.id.substr(0, 2);
    const std::string word = c.id.substr(3);
    if (name == c.id || name == number || name == word ||
        (name.size() == 1 && "0" + name == number))
      return c;
    known += (known.empty() ? "" : ", ") + c.id;
  }
  throw std::invalid_argument("unknown chapter '" + name + "' (known: " + known + ")");
}

std::unique_ptr<Stepper> make_stepper(const std::string& chapter, const Scene& scene,
                                      const SolverSettings& settings) {
  return find_chapter(chapter).make(scene, settings);
}

}  // namespace fem
