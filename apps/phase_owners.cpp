#include "apps/phase_owners.hpp"

#include <fstream>
#include <functional>
#include <iostream>
#include <iterator>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "chapters/registry.hpp"
#include "common/cli.hpp"

namespace fem {

namespace {

constexpr const char* kBegin = "<!-- phase-owners:begin -->\n";
constexpr const char* kEnd = "<!-- phase-owners:end -->";

// A part's chapter as its number where it is a chapter of the course, else its folder.
std::string chapter_label(const std::string& folder) {
  for (const ChapterInfo& c : chapters())
    if (c.id == folder && c.variant_of.empty()) return folder.substr(0, 2);
  return folder;
}

// One cell: the parts that run the phase, each "NN: name", the latest chapter first.
std::string cell(const ChapterInfo& chapter, const std::string& phase) {
  if (chapter.owners.empty()) return chapter.id.substr(0, 2) + ": `step`";
  std::multimap<std::string, std::string, std::greater<>> parts;  // by chapter, latest first
  for (const PhaseOwner& o : chapter.owners)
    if (o.phase == phase) parts.emplace(chapter_label(o.chapter), o.role + " (" + o.name + ")");
  if (parts.empty()) return "none";
  std::string out;
  for (const auto& [label, what] : parts) out += (out.empty() ? "" : "; ") + label + ": " + what;
  return out;
}

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read " + path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// FILE's text with the table between its markers; throws if it has none.
std::string with_table(const std::string& text, const std::string& path) {
  const std::size_t begin = text.find(kBegin), end = text.find(kEnd);
  if (begin == std::string::npos || end == std::string::npos || end < begin)
    throw std::runtime_error(path + " has no phase-owners markers");
  const std::size_t from = begin + std::string(kBegin).size();
  return text.substr(0, from) + phase_owners_table() + text.substr(end);
}

}  // namespace

std::string phase_owners_table() {
  // The poster's phases, then the whole step (the parts around the phases: order and team).
  static const char* const kPhases[] = {"forces",      "dfdx",  "compose",
                                        "constraints", "solve", "step"};
  std::ostringstream out;
  out << "| chapter |";
  for (const char* p : kPhases) out << " " << p << " |";
  out << "\n| --- |";
  for (std::size_t k = 0; k < std::size(kPhases); ++k) out << " --- |";
  out << "\n";
  for (const ChapterInfo& c : chapters()) {
    if (!c.variant_of.empty()) continue;
    out << "| " << c.id.substr(0, 2) << " |";
    for (const char* p : kPhases) out << " " << cell(c, p) << " |";
    out << "\n";
  }
  return out.str();
}

int phase_owners_command(int argc, char** argv) {
  const std::string program = "fem_lessons phase-owners";
  ArgParser args(program,
                 "Which chapter's code runs each phase of each chapter's step, from the "
                 "steppers' recipes: prints the table, or writes or checks it between a file's "
                 "phase-owners markers.");
  args.option("write", "FILE", "write the table between FILE's markers", "");
  args.option("check", "FILE", "exit 1 if FILE's table is not this one", "");
  return run_program(program, [&] {
    if (!args.parse(argc, argv)) return 0;
    const std::string write = args.get("write"), check = args.get("check");
    if (!write.empty()) {
      const std::string text = read_file(write), updated = with_table(text, write);
      if (updated != text) std::ofstream(write) << updated;
      std::cout << "wrote the phase-owners table of " << write << "\n";
      return 0;
    }
    if (!check.empty()) {
      const std::string text = read_file(check);
      if (with_table(text, check) == text) return 0;
      std::cerr << check << ": the phase-owners table is stale (fem_lessons phase-owners --write "
                << check << ")\n";
      return 1;
    }
    std::cout << phase_owners_table();
    return 0;
  });
}

}  // namespace fem
