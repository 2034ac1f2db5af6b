// Catch2 2 and 3 from one test tree. Debian 12 ships Catch2 2.13 (one header,
// <catch2/catch.hpp>); Ubuntu 24.04, Fedora, Arch, Homebrew and vcpkg ship Catch2 3 (a
// compiled library and one header per feature). tests/CMakeLists.txt finds either and sets
// FEM_CATCH2_MAJOR; every test file includes this header instead of Catch2's, and uses the
// names both versions share plus the few below where they differ:
//   Approx                  global in Catch2 2, Catch::Approx in 3 (made global here too)
//   test::contains_text(s)  a string matcher: Catch::Matchers::Contains in 2, ContainsSubstring
//                           in 3 (where Contains is the matcher of a range's elements)
//   test::register_test_case(name, tags, body)  a test case made at run time (AutoReg takes
//                           a raw pointer in 2, Catch's own unique_ptr in 3)
// tests/catch_main.cpp defines FEM_CATCH_MAIN before including it: Catch2 2's implementation
// is compiled there (CATCH_CONFIG_RUNNER), Catch2 3's session and listener headers come in.
#pragma once

#ifndef FEM_CATCH2_MAJOR
#error "FEM_CATCH2_MAJOR is set by tests/CMakeLists.txt from the Catch2 that CMake found"
#endif

#include <deque>
#include <functional>
#include <string>
#include <utility>

#if FEM_CATCH2_MAJOR >= 3
#include <catch2/catch_approx.hpp>
#include <catch2/catch_test_macros.hpp>
#include <catch2/matchers/catch_matchers_string.hpp>
#ifdef FEM_CATCH_MAIN
#include <catch2/catch_session.hpp>
#include <catch2/reporters/catch_reporter_event_listener.hpp>
#include <catch2/reporters/catch_reporter_registrars.hpp>
#endif
using Catch::Approx;  // as Catch2 2 declares it
#else
#ifdef FEM_CATCH_MAIN
// Debian's Catch2WithMain is built without benchmarking support, so the tests keep their
// own main with it.
#define CATCH_CONFIG_RUNNER
#define CATCH_CONFIG_ENABLE_BENCHMARKING
#endif
#include <catch2/catch.hpp>
#endif

namespace fem::test {

// A matcher for "the string contains `text`" (CHECK_THAT, CHECK_THROWS_WITH).
inline auto contains_text(const std::string& text) {
#if FEM_CATCH2_MAJOR >= 3
  return Catch::Matchers::ContainsSubstring(text);
#else
  return Catch::Matchers::Contains(text);
#endif
}

#ifdef FEM_CATCH_MAIN
#if FEM_CATCH2_MAJOR >= 3
using EventListenerBase = Catch::EventListenerBase;
#else
using EventListenerBase = Catch::TestEventListenerBase;
#endif
#endif

// Registers a test case made at run time (one per chapter the build found, say): `body`
// runs as the test case named `name` with the tags `tags` ("[a][b]"). Call it before
// Catch2's session starts, i.e. from a static initializer.
inline void register_test_case(std::string name, std::string tags, std::function<void()> body,
                               const Catch::SourceLineInfo& where) {
  class Invoker final : public Catch::ITestInvoker {
   public:
    explicit Invoker(std::function<void()> body) : body_(std::move(body)) {}
    void invoke() const override { body_(); }

   private:
    std::function<void()> body_;
  };
  // Catch2 keeps references to the name and the tags (StringRef) for the whole run: they
  // live here, in a deque, which never moves its elements.
  static std::deque<std::string> texts;
  texts.push_back(std::move(name));
  const std::string& kept_name = texts.back();
  texts.push_back(std::move(tags));
  const std::string& kept_tags = texts.back();
  // Catch2 owns the invoker from here on.
#if FEM_CATCH2_MAJOR >= 3
  Catch::AutoReg(Catch::Detail::unique_ptr<Catch::ITestInvoker>(new Invoker(std::move(body))),
                 where, Catch::StringRef(), Catch::NameAndTags{kept_name, kept_tags});
#else
  Catch::AutoReg(new Invoker(std::move(body)), where, Catch::StringRef(),
                 Catch::NameAndTags{kept_name, kept_tags});
#endif
}

}  // namespace fem::test
