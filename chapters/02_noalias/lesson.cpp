// Chapter 02's lesson table: `fem_lessons noalias` (heap allocations of each vector statement,
// before and after).
#include "chapters/02_noalias/lesson.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <iomanip>
#include <memory>
#include <sstream>
#include <string>

#include "chapters/02_noalias/statements.hpp"
#include "common/lesson.hpp"

namespace fem::ch02 {

namespace {

std::string noalias_table(const Scene& scene) {
  std::ostringstream out;
  out << "| chapter 01 statement | allocations | chapter 02 rewrite | allocations |\n"
      << "| --- | ---: | --- | ---: |\n";
  for (const auto& c : ch02::count_statements(scene))
    out << "| " << code(c.before_code) << " | " << c.before << " | " << code(c.after_code) << " | "
        << c.after << " |\n";
  return out.str();
}

}  // namespace

std::vector<Lesson> lessons() {
  return {{"noalias",
           "allocations of each vector statement of chapter 01 and its chapter 02 rewrite",
           "meshes/test_beam.msh", nullptr,
           [](const LessonRun& run) { return noalias_table(run.scene); }}};
}

}  // namespace fem::ch02
