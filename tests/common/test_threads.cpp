// Chapters 01-08 run on one thread in every program: the registry steps a stepper whose
// uses_threads() is false inside a OneThreadScope (on_one_thread, common/stepper.hpp), so
// Eigen's own OpenMP kernels (the row-major sparse times dense product of chapter 06,
// Eigen/src/SparseCore/SparseDenseProduct.h) stay on one thread too. And the registry's
// order: each variant right after its original.
#include <Eigen/Core>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>

#include "chapters/06_custom_pcg/stepper.hpp"
#include "common/threads.hpp"
#include "support.hpp"

using namespace fem;

namespace {

// The threads of this process (Linux: /proc/self/task). libgomp keeps the threads of a team
// for the next region, so a parallel region that ran on two threads leaves one more here.
int process_threads() {
  int n = 0;
  for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator("/proc/self/task"))
    ++n;
  return n;
}

// Records the thread counts its step sees.
class Probe final : public Stepper {
 public:
  Probe(const Scene& scene, bool threaded) : Stepper(scene), threaded_(threaded) {}
  void step(State&) override {
    openmp = max_threads();
    eigen = Eigen::nbThreads();
  }
  const StepProfile& profile() const override { return profile_; }
  bool uses_threads() const override { return threaded_; }
  int openmp = 0, eigen = 0;

 private:
  bool threaded_;
  StepProfile profile_;
};

// OMP_NUM_THREADS as the test found it, put back when the test ends (however it ends).
class KeptThreadEnvironment {
 public:
  KeptThreadEnvironment() {
    if (const char* value = std::getenv("OMP_NUM_THREADS")) value_ = value;
  }
  ~KeptThreadEnvironment() {
    if (value_)
      ::setenv("OMP_NUM_THREADS", value_->c_str(), 1);
    else
      ::unsetenv("OMP_NUM_THREADS");
  }
  KeptThreadEnvironment(const KeptThreadEnvironment&) = delete;
  KeptThreadEnvironment& operator=(const KeptThreadEnvironment&) = delete;

 private:
  std::optional<std::string> value_;
};

}  // namespace

TEST_CASE("on_one_thread: a single-threaded stepper's step sees one OpenMP and one Eigen thread",
          "[threads]") {
  if (!openmp_enabled()) {
    SUCCEED("built without OpenMP: every chapter runs on one thread");
    return;
  }
  const Scene scene = test::test_scene("cantilever");
  const ThreadCountScope three(3);
  State state = rest_state(scene);
  auto single = std::make_unique<Probe>(scene, false);
  Probe& seen = *single;
  auto wrapped = on_one_thread(std::move(single), scene);
  wrapped->step(state);
  CHECK(seen.openmp == 1);
  CHECK(seen.eigen == 1);
  // Restored after the step: the next parallel chapter gets the program's count.
  CHECK(max_threads() == 3);
  CHECK(Eigen::nbThreads() == 3);
  CHECK_FALSE(wrapped->uses_threads());

  auto threaded = std::make_unique<Probe>(scene, true);
  Probe& seen_threaded = *threaded;
  auto kept = on_one_thread(std::move(threaded), scene);
  CHECK(kept.get() == &seen_threaded);  // not wrapped
  kept->step(state);
  CHECK(seen_threaded.openmp == 3);
}

// Counts the threads of the process, so it needs a process in which no parallel region has
// run before it: ctest runs every test case in a process of its own.
TEST_CASE("chapter 06 from the registry runs on one thread when OpenMP has two", "[threads]") {
  if (!openmp_enabled()) {
    SUCCEED("built without OpenMP: every chapter runs on one thread");
    return;
  }
  // Eigen threads the row-major product above 20000 non-zeros: beam_500's system has more
  // (the test mesh's has fewer).
  const Scene scene = test::test_scene("cantilever", load_mesh(test::mesh_path("beam_500.msh")));
  const ThreadCountScope two(2);
  ch06::CustomPcgStepper direct(scene, {});
  State direct_state = rest_state(scene);
  {
    const OneThreadScope one;  // its first step must not open a region yet
    direct.step(direct_state);
  }
  REQUIRE(direct.system_matrix().nonZeros() > 20000);
  const int before = process_threads();  // no parallel region has run yet in this process
  INFO("threads of the process before the steps: " << before);

  // As fem_sim and the viewer create it: through the registry, at OpenMP's count of 2.
  auto stepper = make_stepper("06", scene);
  State state = rest_state(scene);
  for (int k = 0; k < 3; ++k) stepper->step(state);
  CHECK(process_threads() == before);

  // The probe can see a second thread: the same chapter stepped directly, with Eigen's count
  // at 2, opens Eigen's parallel region and leaves libgomp's second thread behind.
  Eigen::setNbThreads(2);
  direct.step(direct_state);
  Eigen::setNbThreads(0);
  CHECK(process_threads() == before + 1);
}

TEST_CASE("the registry lists each variant right after its original", "[registry]") {
  const auto info = [](std::string id, std::string variant_of) {
    return ChapterInfo{std::move(id), "", {}, std::move(variant_of), "", {}};
  };
  // "10_mine" sorts before "10_multigrid" by name, and must still come after it.
  const auto sorted = detail::in_course_order(
      {info("09_threads", ""), info("10_mine", "10_multigrid"), info("09_a", "09_threads"),
       info("10_multigrid", ""), info("10_aaa", "10_multigrid")});
  std::vector<std::string> ids;
  for (const auto& c : sorted) ids.push_back(c.id);
  CHECK(ids == std::vector<std::string>{"09_threads", "09_a", "10_multigrid", "10_aaa", "10_mine"});
  // And the real list: every variant follows its original or a variant of it.
  const auto& list = chapters();
  for (std::size_t i = 0; i < list.size(); ++i) {
    if (list[i].variant_of.empty()) continue;
    REQUIRE(i > 0);
    const std::string before =
        list[i - 1].variant_of.empty() ? list[i - 1].id : list[i - 1].variant_of;
    CHECK(before == list[i].variant_of);
  }
}

TEST_CASE(
    "OMP_NUM_THREADS is checked as --threads is: refused above the limit, warned above "
    "the hardware threads",
    "[threads]") {
  const KeptThreadEnvironment kept;
  const auto set = [](int n) { ::setenv("OMP_NUM_THREADS", std::to_string(n).c_str(), 1); };
  set(thread_limit() + 1);
  CHECK_THROWS_WITH(check_thread_environment(),
                    test::contains_text("OMP_NUM_THREADS=" + std::to_string(thread_limit() + 1)) &&
                        test::contains_text("--threads"));
  if (openmp_enabled() && thread_limit() > static_cast<int>(hardware_threads())) {
    set(static_cast<int>(hardware_threads()) + 1);
    CHECK_THAT(check_thread_environment(), test::contains_text("oversubscribed"));
  }
  set(1);
  CHECK(check_thread_environment().empty());
  ::unsetenv("OMP_NUM_THREADS");
  CHECK(check_thread_environment().empty());
}

TEST_CASE(
    "OMP_NUM_THREADS outside the one form both OpenMP runtimes read is refused, with the value "
    "named",
    "[threads]") {
  const KeptThreadEnvironment kept;
  // Each of these LLVM's libomp aborts on, or reads as a count nobody asked for.
  for (const char* value : {"", " ", "+2", "-1", "0", "1.5", "2abc", "abc", "2 3", "2,", ",2",
                            "99999999999999999999", "2000000", "\xef\xbc\x92"}) {
    CAPTURE(value);
    ::setenv("OMP_NUM_THREADS", value, 1);
    CHECK_THROWS_WITH(thread_environment_count(),
                      test::contains_text(std::string("OMP_NUM_THREADS='") + value + "'") &&
                          test::contains_text("not a thread count"));
    CHECK_THROWS_AS(check_thread_environment(), std::invalid_argument);
  }
  // ... and these both read as the same count.
  for (const auto& [value, count] : std::vector<std::pair<const char*, int>>{
           {"2", 2}, {" 2 ", 2}, {"02", 2}, {"1,1,1", 1}, {"3 , 1", 3}, {"1048576", 1 << 20}}) {
    CAPTURE(value);
    ::setenv("OMP_NUM_THREADS", value, 1);
    CHECK(thread_environment_count() == count);
  }
  ::unsetenv("OMP_NUM_THREADS");
  CHECK(thread_environment_count() == 0);
}
