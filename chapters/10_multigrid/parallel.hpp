// The two pieces of OpenMP this chapter needs, behind a guard so that the chapter also
// builds (and runs on one thread) without OpenMP.
#pragma once

#ifdef _OPENMP
#include <omp.h>
#endif

namespace fem::ch10 {

// Runs body() on every thread of a team, or straight on the calling thread when the team
// would have one thread. Why not always a region: libgomp keeps the last team for reuse
// only when it has more than one thread (gomp_team_end in libgomp/team.c frees a team of
// one), so a region of one thread costs a malloc and a free each time, and one thread
// needs no region. The worksharing loops and barriers inside body() are orphaned
// constructs: outside a region they run as a team of one (every iteration, no wait).
template <class Body>
void run_parallel(Body&& body) {
#ifdef _OPENMP
  if (omp_get_max_threads() > 1) {
#pragma omp parallel
    body();
    return;
  }
#endif
  body();
}

}  // namespace fem::ch10
