// `fem_lessons phase-owners`: which chapter's code runs each phase of each chapter's step, from
// the registry (chapter 08 on: the parts each recipe names; before: the chapter's own step()),
// as the table between chapters/README.md's phase-owners markers.
#pragma once

#include <string>

namespace fem {

// The markdown table: a row per chapter of the course (variants aside), a column per phase.
std::string phase_owners_table();

// fem_lessons phase-owners [--write FILE | --check FILE]: prints the table, writes it between
// FILE's markers, or exits 1 if FILE's table differs (the docs test).
int phase_owners_command(int argc, char** argv);

}  // namespace fem
