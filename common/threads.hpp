// How many threads the parallel chapters use, and the one thread of the others.
//
// A chapter whose stepper says uses_threads() (09 on) runs every OpenMP parallel region on
// this count. Every other chapter (01-08) runs on one thread in every program: the registry
// (chapters/registry.cpp) wraps its stepper so that each step runs inside a OneThreadScope.
// That matters even for chapters without a `#pragma omp` of their own: Eigen runs a
// row-major sparse matrix times a dense vector (chapter 06's A.transpose() * p) as an OpenMP
// `parallel for` over rows when Eigen::nbThreads() > 1 and the matrix has more than 20000
// non-zeros (sparse_time_dense_product_impl in Eigen/src/SparseCore/SparseDenseProduct.h),
// and Eigen::nbThreads() is omp_get_max_threads() unless Eigen::setNbThreads set it
// (manage_multi_threading in Eigen/src/Core/products/Parallelizer.h).
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

// The most threads a program accepts on its command line: kOversubscription times the
// hardware threads. More threads than cores only wait for each other at every barrier, each
// barrier waiting for threads the system has not scheduled yet: a count far above the cores
// is a typo, refused at once rather than run for many times as long.
constexpr int kOversubscription = 4;
int thread_limit();
// Checks a thread count asked for on the command line before any work: throws
// std::invalid_argument for n < 1, n > 1 without OpenMP, or n > thread_limit(); returns a
// warning to print when n is more than the hardware threads (oversubscribed), else "".
std::string check_thread_count(int n);

// The same check of the count the environment asks for (OMP_NUM_THREADS, its first number),
// which every program without --threads runs on: throws std::invalid_argument naming the
// variable when it is not a count (thread_environment_count) or above thread_limit(), returns
// the warning above the hardware threads, "" when the variable is unset.
std::string check_thread_environment();
// The count OMP_NUM_THREADS asks for (its first number), 0 when unset. Throws
// std::invalid_argument when it is set but not positive whole numbers separated by commas
// (blank, "+2", "1.5", "2abc", past 2^20): the one form both OpenMP runtimes read alike (LLVM's
// libomp aborts on the others at its first call), so every program checks it before that call,
// with or without --threads.
int thread_environment_count();

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

// Whether the thread count in force was asked for (--threads N, OMP_NUM_THREADS, a Body's
// `threads`): then it is the count that steps, and a team that would choose its own size
// (chapter 09's AdaptiveTeam, which takes one thread while that is faster) keeps it. Per
// thread, as OpenMP's count is: set_thread_count_asked for the thread that calls it (a
// program's main thread), AskedThreadsScope for one step (the library's Body).
bool thread_count_asked();
void set_thread_count_asked(bool asked);
class AskedThreadsScope {
 public:
  explicit AskedThreadsScope(bool asked) : previous_(thread_count_asked()) {
    set_thread_count_asked(asked);
  }
  ~AskedThreadsScope() { set_thread_count_asked(previous_); }
  AskedThreadsScope(const AskedThreadsScope&) = delete;
  AskedThreadsScope& operator=(const AskedThreadsScope&) = delete;

 private:
  bool previous_;
};

// One thread for a scope, OpenMP's and Eigen's own (Eigen::setNbThreads), both restored at
// its end: what a single-threaded chapter's step runs in. Costs two stores and two loads.
class OneThreadScope {
 public:
  OneThreadScope();
  ~OneThreadScope();
  OneThreadScope(const OneThreadScope&) = delete;
  OneThreadScope& operator=(const OneThreadScope&) = delete;

 private:
  int openmp_, eigen_;
};

}  // namespace fem
