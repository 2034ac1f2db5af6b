// The chapter registry: the apps and the tests create steppers by chapter name.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "common/stepper.hpp"

namespace fem {

struct ChapterInfo {
  std::string id;     // directory name, e.g. "01_naive"
  std::string title;  // one line: the idea of the chapter
  std::function<std::unique_ptr<Stepper>(const Scene&, const SolverSettings&)> make;
};

// Every chapter present, in order.
const std::vector<ChapterInfo>& chapters();

// Accepts "01_naive", "01", "1" or "naive"; throws std::invalid_argument listing the
// known chapters otherwise.
const ChapterInfo& find_chapter(const std::string& name);

std::unique_ptr<Stepper> make_stepper(const std::string& chapter, const Scene& scene,
                                      const SolverSettings& settings = {});

}  // namespace fem
