#include "apps/phase_owners.hpp"

#include <functional>
#include <iostream>
#include <map>
#include <sstream>
#include <string>

#include "chapters/registry.hpp"
#include "common/cli.hpp"
#include "common/stepper.hpp"

namespace fem {

namespace {

constexpr const char* kMarkers = "phase-owners";  // <!-- phase-owners:begin/end -->

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

}  // namespace

std::string phase_owners_table() {
  // The profile's phases, the whole step last (the parts around the phases: order and team).
  const auto& phases = StepProfile::phases();
  std::ostringstream out;
  out << "| chapter |";
  for (const StepProfile::Phase& p : phases) out << " " << p.name << " |";
  out << "\n| --- |";
  for (std::size_t k = 0; k < phases.size(); ++k) out << " --- |";
  out << "\n";
  for (const ChapterInfo& c : chapters()) {
    if (!c.variant_of.empty()) continue;
    out << "| " << c.id.substr(0, 2) << " |";
    for (const StepProfile::Phase& p : phases) out << " " << cell(c, p.name) << " |";
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
    const std::string write = args.get_nonempty("write"), check = args.get_nonempty("check");
    if (!write.empty()) {
      write_between_markers(write, kMarkers, phase_owners_table());
      std::cout << "wrote the phase-owners table of " << write << "\n";
      return 0;
    }
    if (!check.empty()) {
      if (read_between_markers(check, kMarkers) == "\n" + phase_owners_table()) return 0;
      std::cerr << check << ": the phase-owners table is stale (fem_lessons phase-owners --write "
                << check << ")\n";
      return 1;
    }
    std::cout << phase_owners_table();
    return 0;
  });
}

}  // namespace fem
