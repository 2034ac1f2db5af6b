// Debian's Catch2WithMain is built without benchmarking support, so the tests keep
// their own main with CATCH_CONFIG_ENABLE_BENCHMARKING.
#define CATCH_CONFIG_MAIN
#define CATCH_CONFIG_ENABLE_BENCHMARKING
#include <catch2/catch.hpp>
