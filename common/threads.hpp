// How many threads the parallel chapters use. Chapters 01-08 are single-threaded whatever
// this says; from chapter 09 on every OpenMP parallel region takes this count.
//
// The count is OpenMP's: OMP_NUM_THREADS when the programs get no --threads, all hardware
// threads when neither is given. Without OpenMP (FEM_OPENMP=OFF, or a compiler without it)
// everything runs on one thread and set_threads only accepts 1.
#pragma once

#include <string>

namespace fem {

bool openmp_enabled();
// The number of threads the next parallel region will use (1 without OpenMP).
int max_threads();
// Sets it for the whole program (omp_set_num_threads); throws std::invalid_argument for
// n < 1, or n > 1 in a build without OpenMP.
void set_threads(int n);

// Sets the thread count for a scope and restores the previous one: tests, benchmarks.
class ThreadCountScope {
 public:
  explicit ThreadCountScope(int n) : previous_(max_threads()) { set_threads(n); }
  ~ThreadCountScope() { set_threads(previous_); }
  ThreadCountScope(const ThreadCountScope&) = delete;
  ThreadCountScope& operator=(const ThreadCountScope&) = delete;

 private:
  int previous_;
};

}  // namespace fem
