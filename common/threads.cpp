#include "common/threads.hpp"

#include <stdexcept>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace fem {

bool openmp_enabled() {
#ifdef _OPENMP
  return true;
#else
  return false;
#endif
}

int max_threads() {
#ifdef _OPENMP
  return omp_get_max_threads();
#else
  return 1;
#endif
}

void set_threads(int n) {
  if (n < 1) throw std::invalid_argument("the thread count must be >= 1, got " + std::to_string(n));
#ifdef _OPENMP
  omp_set_num_threads(n);
#else
  if (n > 1)
    throw std::invalid_argument("this build has no OpenMP (FEM_OPENMP=OFF): only 1 thread, not " +
                                std::to_string(n));
#endif
}

}  // namespace fem
