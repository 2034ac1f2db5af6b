// The checks every chapter passes, registered once per chapter the build found (the
// registry is generated from chapters/*/), so a new chapter or a student's variant made with
// ./tutorial.sh variant is tested without a line of test code: it matches chapter 01 on both
// scenes, and its allocations per step are deterministic (none if its original has none).
#include <catch2/catch.hpp>
#include <deque>
#include <string>
#include <utility>

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

// A Catch2 test case bound to one chapter: Catch2 2.x registers function pointers, so a
// chapter-parametrized case is an invoker object holding the chapter.
class ChapterTest final : public Catch::ITestInvoker {
 public:
  ChapterTest(void (*check)(const ChapterInfo&), const ChapterInfo& chapter)
      : check_(check), chapter_(chapter) {}
  void invoke() const override { check_(chapter_); }

 private:
  void (*check_)(const ChapterInfo&);
  const ChapterInfo& chapter_;
};

// Names and tags live as long as the program (a deque never moves its elements). Catch2
// takes ownership of the invoker (its TestCase holds it in a shared_ptr), hence the new.
const bool registered = [] {
  static std::deque<std::string> texts;
  for (const ChapterInfo& chapter : chapters()) {
    const std::pair<const char*, void (*)(const ChapterInfo&)> checks[] = {
        {"matches chapter 01 on both scenes over 50 steps", matches_ch01},
        {"allocations per step are the same every step", allocations}};
    for (const auto& [what, check] : checks) {
      texts.push_back(chapter.id + ": " + what);
      const std::string& name = texts.back();
      texts.push_back("[every_chapter][" + chapter.id + "]");
      const std::string& tags = texts.back();
      Catch::AutoReg(new ChapterTest(check, chapter), CATCH_INTERNAL_LINEINFO, Catch::StringRef(),
                     Catch::NameAndTags{name, tags});
    }
  }
  return true;
}();

}  // namespace
