// The course's list: what the course measures of each chapter, beside the registry's steppers
// (chapters/registry.hpp). Generated with the registry by chapters/registry.cmake into
// fem_chapters (the course), so the library (fem_steppers) holds no lesson and no work count:
// a program on femcourse::simulator links the steppers and nothing the course measures them
// with (JSON, the command line, the machine record).
#pragma once

#include <string>
#include <vector>

#include "chapters/registry.hpp"
#include "chapters/work.hpp"
#include "common/lesson.hpp"

namespace fem {

// A chapter of the registry with the course's hooks into it.
struct CourseChapter {
  const ChapterInfo* chapter = nullptr;
  // The measurements behind the chapter's lesson tables (its lesson.hpp), or nullptr.
  std::vector<Lesson> (*lessons)() = nullptr;
  // How the chapter counts its own work per phase (chapters/work.hpp), from the data of the
  // stepper its `make` returns: count_work found by argument-dependent lookup (a chapter
  // 01-07 stepper's own; from chapter 08 on the sum of its recipe's parts' counts, chapter 08's
  // work.hpp), and the kernels of its parts that the roofline times alone; empty if none counts.
  ChapterWork work;
};

// Every chapter of chapters(), in its order, with its hooks.
const std::vector<CourseChapter>& course_chapters();

// The hooks of a chapter of chapters() (by its id); throws std::invalid_argument for another.
const CourseChapter& course_of(const ChapterInfo& chapter);

namespace detail {
// One chapter's hooks by its id, as the build writes them (chapters/registry.cmake).
struct CourseHooks {
  std::string id;
  std::vector<Lesson> (*lessons)() = nullptr;
  ChapterWork work;
};
// Written by the build, in directory order.
std::vector<CourseHooks> discovered_course();
// The registry's chapters joined with their hooks by id; throws std::logic_error for a
// chapter without hooks or hooks without a chapter (two lists of one generator disagreeing).
std::vector<CourseChapter> joined(const std::vector<ChapterInfo>& chapters,
                                  std::vector<CourseHooks> hooks);
}  // namespace detail

}  // namespace fem
