// Debian's Catch2WithMain is built without benchmarking support, so the tests keep
// their own main with CATCH_CONFIG_ENABLE_BENCHMARKING. It also refuses a run in which no
// test case matched: Catch2 2.x exits 0 then, so a ctest entry whose name had been mangled
// (a ';' splits a name in CMake) would pass without running anything.
#define CATCH_CONFIG_RUNNER
#define CATCH_CONFIG_ENABLE_BENCHMARKING
#include <catch2/catch.hpp>
#include <iostream>

namespace {

bool ran_no_test_case = false;

struct NoTestCaseListener : Catch::TestEventListenerBase {
  using TestEventListenerBase::TestEventListenerBase;
  void testRunEnded(const Catch::TestRunStats& stats) override {
    ran_no_test_case = stats.totals.testCases.total() == 0;
  }
};

}  // namespace

CATCH_REGISTER_LISTENER(NoTestCaseListener)

int main(int argc, char** argv) {
  const int failures = Catch::Session().run(argc, argv);
  if (ran_no_test_case) {
    std::cerr << "error: no test case matched the filter\n";
    return 1;
  }
  return failures;
}
