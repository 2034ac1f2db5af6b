// The checks every chapter passes, registered once per chapter the build found (the
// registry is generated from chapters/*/), so a new chapter or a student's variant made with
// ./tutorial.sh variant is tested without a line of test code: it matches chapter 01 on both
// scenes, and its allocations per step are deterministic (none if its original has none).
#include <string>
#include <utility>

#include "catch2_compat.hpp"
#include "support.hpp"

namespace {

using namespace fem;

void matches_ch01(const ChapterInfo& chapter) {
  for (const char* name : {"cantilever", "sliding"})
    test::check_matches_ch01(chapter.id, test::test_scene(name));
}

void allocations(const ChapterInfo& chapter) {
  FEM_REQUIRE_ALLOCATION_COUNTER();
  for (const char* name : {"cantilever", "sliding"}) {
    const Scene scene = test::test_scene(name);
    const long long count = test::allocations_per_step(chapter.id, scene);
    INFO(chapter.id << " on " << name << ": " << count << " allocations per step (-1: not the "
                    << "same every step)");
    CHECK(count >= 0);
    // The chapters from 06 on allocate nothing; a variant of one must keep it that way.
    if (!chapter.variant_of.empty() &&
        test::allocations_per_step(chapter.variant_of, scene) == 0)
      CHECK(count == 0);
  }
}

// One test case per chapter and check, made at run time from the registry.
const bool registered = [] {
  for (const ChapterInfo& chapter : chapters()) {
    const std::pair<const char*, void (*)(const ChapterInfo&)> checks[] = {
        {"matches chapter 01 on both scenes over 50 steps", matches_ch01},
        {"allocations per step are the same every step", allocations}};
    for (const auto& [what, check] : checks)
      test::register_test_case(chapter.id + ": " + what, "[every_chapter][" + chapter.id + "]",
                               [check = check, &chapter] { check(chapter); },
                               Catch::SourceLineInfo(__FILE__, __LINE__));
  }
  return true;
}();

}  // namespace
