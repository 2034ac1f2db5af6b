#include "chapters/course.hpp"

#include <algorithm>
#include <stdexcept>

namespace fem {

namespace detail {

std::vector<CourseChapter> joined(const std::vector<ChapterInfo>& chapters,
                                  std::vector<CourseHooks> hooks) {
  if (hooks.size() != chapters.size())
    throw std::logic_error("the course lists " + std::to_string(hooks.size()) +
                           " chapters, the registry " + std::to_string(chapters.size()));
  std::vector<CourseChapter> out;
  for (const ChapterInfo& c : chapters) {
    const auto found = std::find_if(hooks.begin(), hooks.end(),
                                    [&c](const CourseHooks& h) { return h.id == c.id; });
    if (found == hooks.end()) throw std::logic_error("the course lists no chapter " + c.id);
    out.push_back({&c, found->lessons, std::move(found->work)});
  }
  return out;
}

}  // namespace detail

const std::vector<CourseChapter>& course_chapters() {
  static const std::vector<CourseChapter> list =
      detail::joined(chapters(), detail::discovered_course());
  return list;
}

const CourseChapter& course_of(const ChapterInfo& chapter) {
  for (const CourseChapter& c : course_chapters())
    if (c.chapter->id == chapter.id) return c;
  throw std::invalid_argument("chapter " + chapter.id + " is not one of chapters()");
}

}  // namespace fem
