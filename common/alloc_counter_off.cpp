// The allocation counter's answers in a program that does not link it (a program built on
// femcourse::simulator alone): nothing is counted. Part of fem_fallbacks (CMakeLists.txt): the
// static linker takes this file only when no object of the program defines these functions,
// so a program that links fem_alloc_counter gets the counter.
#include "common/alloc_counter.hpp"

namespace fem::alloc {

bool enabled() { return false; }
Counts counts() { return {}; }

}  // namespace fem::alloc
