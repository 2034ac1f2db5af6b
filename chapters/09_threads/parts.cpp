// Chapter 09's team and block Jacobi on the row chunks (see parts.hpp).
#include "chapters/09_threads/parts.hpp"

#include <cstdlib>
#include <cstring>

#include "chapters/09_threads/parallel.hpp"
#include "common/threads.hpp"

namespace fem::ch09 {

TeamOfThreads::TeamOfThreads() {
  const char* adaptive = std::getenv("FEM_ADAPTIVE_TEAM");
  adaptive_team_.set_enabled(!(adaptive && std::strcmp(adaptive, "0") == 0));
}

int TeamOfThreads::begin() {
  // The program's count is OpenMP's (--threads, OMP_NUM_THREADS); a step on another team sets
  // it for this thread's regions during the step and puts it back.
  const int given = max_threads();
  // libgomp mallocs a thread's ICV block at its first omp_set_num_threads, once (gomp_icv in
  // libgomp's icv.c): make it in the first step, which the zero-allocation rule leaves out,
  // not in the first step that switches the team.
  if (!steps_taken_++) set_threads(given);
  team_ = adaptive_team_.next(given);
  if (team_ != given) set_threads(team_);
  return given;
}

void TeamOfThreads::end(int given, double step_seconds) {
  if (team_ != given) set_threads(given);
  adaptive_team_.record(step_seconds);
}

void JacobiOnChunks::prepare(const BlockSparseMatrix& A) {
  for (const int c : StaticShare(chunks_.count()))
    invert_rows(A, chunks_.start[c], chunks_.start[c + 1]);
}

void JacobiOnChunks::apply(const Eigen::VectorXd& r, Eigen::VectorXd& s) {
  for (const int c : StaticShare(chunks_.count()))
    apply_rows(chunks_.start[c], chunks_.start[c + 1], r, s);
}

}  // namespace fem::ch09
