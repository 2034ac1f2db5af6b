// The main of every test binary, for Catch2 2 and 3 alike (tests/catch2_compat.hpp). It
// refuses a run in which no test case matched: Catch2 2.x exits 0 then, so a ctest entry
// whose name had been mangled (a ';' splits a name in CMake) would pass without running
// anything. (Catch2 3 refuses such a run itself, with exit code 2; the rule is ours either way.)
#define FEM_CATCH_MAIN
#include <iostream>

#include "catch2_compat.hpp"

namespace {

bool ran_no_test_case = false;

struct NoTestCaseListener : fem::test::EventListenerBase {
  using Base = fem::test::EventListenerBase;
  using Base::Base;
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
