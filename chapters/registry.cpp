#include "chapters/registry.hpp"

#include <algorithm>
#include <stdexcept>
#include <tuple>

namespace fem {

const std::vector<ChapterInfo>& chapters() {
  static const std::vector<ChapterInfo> list = [] {
    std::vector<ChapterInfo> found = detail::in_course_order(detail::discovered_chapters());
    // A single-threaded chapter (01-08) steps on one thread in every program: see
    // on_one_thread (common/stepper.hpp) and why it matters (common/threads.hpp).
    // Each stepper is named by its registry id, the one id it warns under.
    for (ChapterInfo& c : found)
      c.make = [make = std::move(c.make), id = c.id](const Scene& scene,
                                                     const SolverSettings& settings) {
        auto stepper = on_one_thread(make(scene, settings), scene);
        stepper->set_name(id);
        return stepper;
      };
    return found;
  }();
  return list;
}

namespace detail {

std::vector<ChapterInfo> in_course_order(std::vector<ChapterInfo> found) {
  // A variant sorts right after its original (and after any variant before it in name
  // order), so that tables read original, variant: the key is (original, is a variant, id),
  // and "10_mine" comes after "10_multigrid" although it sorts before it by name.
  const auto key = [](const ChapterInfo& c) {
    return std::make_tuple(c.variant_of.empty() ? c.id : c.variant_of, !c.variant_of.empty(), c.id);
  };
  std::stable_sort(found.begin(), found.end(),
                   [&key](const ChapterInfo& a, const ChapterInfo& b) { return key(a) < key(b); });
  return found;
}

}  // namespace detail

const ChapterInfo& latest_chapter() {
  const auto& list = chapters();
  return *std::find_if(list.rbegin(), list.rend(),
                       [](const ChapterInfo& c) { return c.variant_of.empty(); });
}

const ChapterInfo& find_chapter(const std::string& name) {
  std::string known;
  for (const auto& c : chapters())
    if (name == c.id) return c;
  for (const auto& c : chapters()) {
    const std::string number = c.id.substr(0, 2);
    const std::string word = c.id.substr(3);
    const bool by_number = c.variant_of.empty() && (name == number || "0" + name == number);
    if (by_number || name == word) return c;
    known += (known.empty() ? "" : ", ") + c.id;
  }
  throw std::invalid_argument("unknown chapter '" + name + "' (known: " + known + ")");
}

std::vector<const ChapterInfo*> find_chapters(const std::vector<std::string>& names) {
  std::vector<const ChapterInfo*> out;
  if (names.size() == 1 && names[0] == "all") {
    for (const ChapterInfo& c : chapters()) out.push_back(&c);
    return out;
  }
  for (const std::string& name : names) {
    const ChapterInfo* found = &find_chapter(name);
    if (std::find(out.begin(), out.end(), found) != out.end())
      throw std::invalid_argument("the chapter " + found->id + " is named twice");
    out.push_back(found);
  }
  if (out.empty()) throw std::invalid_argument("no chapter named");
  return out;
}

std::unique_ptr<Stepper> make_stepper(const std::string& chapter, const Scene& scene,
                                      const SolverSettings& settings) {
  return find_chapter(chapter).make(scene, settings);
}

}  // namespace fem
