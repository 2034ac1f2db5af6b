#include "common/threads.hpp"

#include <Eigen/Core>
#include <cctype>
#include <cstdlib>
#include <stdexcept>
#include <thread>

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

namespace {
thread_local bool asked_on_this_thread = false;
}  // namespace

bool thread_count_asked() { return asked_on_this_thread; }
void set_thread_count_asked(bool asked) { asked_on_this_thread = asked; }

int thread_limit() {
  const int hardware = static_cast<int>(std::thread::hardware_concurrency());
  return kOversubscription * (hardware > 0 ? hardware : 1);
}

std::string check_thread_count(int n) {
  if (n < 1) throw std::invalid_argument("the thread count must be >= 1, got " + std::to_string(n));
  if (n > 1 && !openmp_enabled())
    throw std::invalid_argument("this build has no OpenMP (FEM_OPENMP=OFF): only 1 thread, not " +
                                std::to_string(n));
#ifdef _OPENMP
  // OMP_THREAD_LIMIT caps every team whatever is asked: a count above it would run on fewer
  // threads than the program says and records.
  if (const int cap = omp_get_thread_limit(); n > cap)
    throw std::invalid_argument(std::to_string(n) + " threads, but OMP_THREAD_LIMIT allows " +
                                std::to_string(cap) + ": unset it, or ask for at most " +
                                std::to_string(cap));
#endif
  const unsigned hardware = std::thread::hardware_concurrency();
  if (n > thread_limit())
    throw std::invalid_argument(
        std::to_string(n) + " threads on a machine with " + std::to_string(hardware) +
        " hardware threads: more than " + std::to_string(kOversubscription) +
        " per hardware thread only wait for each other at every barrier (at most " +
        std::to_string(thread_limit()) + ")");
  if (hardware > 0 && static_cast<unsigned>(n) > hardware)
    return std::to_string(n) + " threads on " + std::to_string(hardware) +
           " hardware threads: oversubscribed, the threads take turns on the cores and wait "
           "for each other at every barrier (expect it slower than " +
           std::to_string(hardware) + ")";
  return "";
}

namespace {

constexpr long kMostThreadsRead = 1L << 20;

// The first count of OMP_NUM_THREADS's value when the value is whole: positive whole numbers up
// to kMostThreadsRead, digits only, separated by commas (nested levels), blanks around each;
// else 0. Only this form do the two OpenMP runtimes read alike. Outside it they part ways: GCC's
// libgomp ignores the value, warning, and runs its default count; LLVM's libomp aborts at its
// first call (signal 6) on "", "+2", "1.5", "2abc" or 20 nines, takes "abc" for a garbage count
// and "2000000" for two million threads (measured with Clang 14's libomp, Debian 12).
int first_of_whole_list(const char* s) {
  int first = 0;
  for (;;) {
    while (std::isspace(static_cast<unsigned char>(*s))) ++s;
    if (!std::isdigit(static_cast<unsigned char>(*s))) return 0;  // no sign, no empty item
    char* end = nullptr;
    const long n = std::strtol(s, &end, 10);
    if (n < 1 || n > kMostThreadsRead) return 0;
    if (first == 0) first = static_cast<int>(n);
    while (std::isspace(static_cast<unsigned char>(*end))) ++end;
    if (*end == '\0') return first;
    if (*end != ',') return 0;
    s = end + 1;
  }
}

}  // namespace

int thread_environment_count() {
  const char* value = std::getenv("OMP_NUM_THREADS");
  if (!value) return 0;
  const int first = first_of_whole_list(value);
  if (first == 0)
    throw std::invalid_argument(
        std::string("OMP_NUM_THREADS='") + value +
        "' is not a thread count: OpenMP's runtimes read whole numbers from 1 to " +
        std::to_string(kMostThreadsRead) +
        " (several, separated by commas, for nested levels) and differ on anything else "
        "(LLVM's aborts, GCC's ignores it); unset it, or set it to a count such as 2 "
        "(--threads N sets the count, but the runtime still reads the variable)");
  return first;
}

std::string check_thread_environment() {
  const int n = thread_environment_count();  // throws for a value that is not a count
  if (n == 0) return "";
  const std::string name = std::string("OMP_NUM_THREADS=") + std::getenv("OMP_NUM_THREADS");
  try {
    const std::string warning = check_thread_count(n);
    return warning.empty() ? "" : name + ": " + warning;
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(name + ": " + e.what() +
                                "; unset it, or give --threads N (which overrides it)");
  }
}

OneThreadScope::OneThreadScope() : openmp_(max_threads()), eigen_(Eigen::nbThreads()) {
#ifdef _OPENMP
  omp_set_num_threads(1);
#endif
  Eigen::setNbThreads(1);
}

OneThreadScope::~OneThreadScope() {
#ifdef _OPENMP
  omp_set_num_threads(openmp_);
#endif
  // Eigen's count follows OpenMP's until a program sets it (Eigen::nbThreads() returns
  // omp_get_max_threads() while the stored count is <= 0, Parallelizer.h): where it was
  // following, it follows again (0), rather than staying frozen at the count of this moment.
  Eigen::setNbThreads(eigen_ == openmp_ ? 0 : eigen_);
}

}  // namespace fem
