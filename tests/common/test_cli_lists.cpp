// The list options of the programs, parsed in one place: ArgParser's get_list/get_int_list,
// the thread-count lists (fem_bench --threads, fem_lessons multigrid --cost-threads) and the
// chapter lists (--chapters, with "all"); and chapter 10's settings checked once, by check().
#include <stdexcept>

#include "chapters/10_multigrid/stepper.hpp"
#include "chapters/registry.hpp"
#include "common/cli.hpp"
#include "common/threads.hpp"
#include "support.hpp"

using namespace fem;

namespace {

ArgParser parsed(const std::string& value) {
  ArgParser args("test", "list options");
  args.option("list", "LIST", "a list", "");
  const char* argv[] = {"test", "--list", value.c_str()};
  args.parse(3, argv);
  return args;
}

}  // namespace

TEST_CASE("get_list skips empty items and get_int_list keeps a repeated count once") {
  CHECK(parsed("09,,12").get_list("list") == std::vector<std::string>{"09", "12"});
  CHECK(parsed("").get_list("list").empty());
  CHECK(parsed("2,1,2").get_int_list("list") == std::vector<int>{2, 1});
  CHECK_THROWS_AS(parsed("1,x").get_int_list("list"), UsageError);
}

TEST_CASE("a thread-count list is checked as --threads is, and none given means 1 and OpenMP's") {
  CHECK(thread_counts_from_args(parsed("1,1"), "list") == std::vector<int>{1});
  CHECK_THROWS_AS(thread_counts_from_args(parsed("0"), "list"), UsageError);
  // Given but naming no count (--threads "$N" with N unset) is a mistake, not the default.
  CHECK_THROWS_WITH(thread_counts_from_args(parsed(""), "list"),
                    test::contains_text("--list '' names no thread count"));
  CHECK_THROWS_AS(thread_counts_from_args(parsed(","), "list"), UsageError);
  ArgParser not_given("test", "list options");
  not_given.option("list", "LIST", "a list", "");
  const char* argv[] = {"test"};
  not_given.parse(1, argv);
  const std::vector<int> defaults = thread_counts_from_args(not_given, "list");
  CHECK(defaults.front() == 1);
  CHECK(defaults.back() == max_threads());
}

TEST_CASE("a chapter list: names, or 'all' for every chapter present, and a repeat refused") {
  CHECK(find_chapters({"all"}).size() == chapters().size());
  const auto two = find_chapters({"12", "01"});
  REQUIRE(two.size() == 2);
  CHECK(two[0]->id.substr(0, 2) == "12");
  CHECK_THROWS_AS(find_chapters({"01", "01_naive"}), std::invalid_argument);
  CHECK_THROWS_AS(find_chapters({}), std::invalid_argument);
}

TEST_CASE("chapter 10's settings are checked once, by check(), the lesson's rule included") {
  ch10::MultigridStepperSettings s;
  CHECK_NOTHROW(ch10::check(s));
  s.multigrid.max_coarse_dofs = 5;  // below one aggregate's modes
  CHECK_THROWS_AS(ch10::check(s), std::invalid_argument);
  s = {};
  s.extrapolation = 3;
  CHECK_THROWS_AS(ch10::check(s), std::invalid_argument);
  s = {};
  s.multigrid.rows.serial_rows = -1;
  CHECK_THROWS_AS(ch10::check(s), std::invalid_argument);
}

TEST_CASE("a number out of a double's range is named as such, not as not finite") {
  CHECK_THROWS_WITH(parsed("1e-320").get_double("list"),
                    test::contains_text("out of a double's range (below 2.2e-308"));
  CHECK_THROWS_WITH(parsed("1e400").get_double("list"),
                    test::contains_text("out of a double's range (above 1.8e+308)"));
  CHECK_THROWS_WITH(parsed("nan").get_double("list"), test::contains_text("expects a finite"));
  CHECK(parsed("1e-300").get_double("list") == 1e-300);
}

TEST_CASE("an integer out of an int's range is named as such, not as not an integer") {
  CHECK_THROWS_WITH(parsed("1000000000000").get_int("list"),
                    test::contains_text("1000000000000 is out of range (at most 2147483647)"));
  CHECK_THROWS_WITH(parsed("1.5").get_int("list"), test::contains_text("expects an integer"));
  CHECK(parsed("2147483647").get_int("list") == 2147483647);
}
