// A small command-line parser shared by the apps: "--name value" options with
// defaults, flags, --help, and clear errors for anything else.
#pragma once

#include <functional>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/scene.hpp"
#include "common/stepper.hpp"

namespace fem {

struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The whole of s as a number; nullopt when it is none (empty, trailing text, out of range).
std::optional<int> parse_int(const std::string& s);
std::optional<double> parse_double(const std::string& s);

class ArgParser {
 public:
  ArgParser(std::string program, std::string summary);
  void option(const std::string& name, const std::string& value_name, const std::string& help,
              const std::string& default_value);
  void flag(const std::string& name, const std::string& help);

  // Returns false when --help was asked for (the help is printed); throws UsageError
  // for an unknown option or a missing value.
  bool parse(int argc, const char* const* argv);

  const std::string& get(const std::string& name) const;
  // As get(), but an option given with an empty value ("--report $OUT", OUT unset) is refused
  // rather than read as not given: a file or a drag the user asked for would silently vanish.
  const std::string& get_nonempty(const std::string& name) const;
  double get_double(const std::string& name) const;  // throws UsageError if not a number
  int get_int(const std::string& name) const;        // throws UsageError if not an integer
  bool has_flag(const std::string& name) const;
  bool has_option(const std::string& name) const { return options_.count(name) > 0; }
  // On the command line (with any value, "" included), not only its default.
  bool given(const std::string& name) const { return options_.at(name).set; }
  // The option's comma-separated items, empty ones skipped: "09,,12" -> {"09", "12"}; "" -> {}.
  std::vector<std::string> get_list(const std::string& name) const;
  // The items as integers, a repeated one kept once (at its first place); throws UsageError
  // for an item that is not an integer.
  std::vector<int> get_int_list(const std::string& name) const;
  std::string help() const;

 private:
  struct Option {
    std::string value_name, help, value;
    bool is_flag = false;
    bool set = false;
  };
  std::string program_, summary_;
  std::vector<std::string> order_;
  std::map<std::string, Option> options_;
};

// The options every app shares: --scene --mesh --E --nu --rho --dt --alpha --beta.
void add_scene_options(ArgParser& args, const std::string& default_mesh);
// Builds and validates the scene they describe; throws UsageError with the reason.
Scene scene_from_args(const ArgParser& args);

// --tol and --max-iters.
void add_solver_options(ArgParser& args);
SolverSettings solver_from_args(const ArgParser& args);

// --threads N: the thread count of the parallel chapters (09 on). Without it OMP_NUM_THREADS;
// without either the count is not asked for, and the steppers choose (common/threads.hpp).
void add_thread_option(ArgParser& args);
// Applies --threads when given (or OMP_NUM_THREADS) and marks the count asked for
// (set_thread_count_asked), so that it is the count that steps; returns the thread count in
// use. Throws UsageError for an empty value, a count below 1, above 1 in a build without
// OpenMP, above OMP_THREAD_LIMIT or above thread_limit() (common/threads.hpp); warns on stderr
// above the hardware threads.
int threads_from_args(const ArgParser& args);
// Without --threads: OMP_NUM_THREADS checked by the same rule (check_thread_environment):
// throws UsageError above the limit, warns on stderr above the hardware threads.
void apply_thread_environment();

// A run that will take longer than a minute says so before it goes on, from its first timed
// step: "<program>: this run will take about 7 min (N steps at 0.42 s each)". Prints nothing
// for a shorter one. Flushed, as every progress line is, so that it reaches a file as it
// reaches a terminal.
void announce_long_run(const std::string& program, double seconds_per_step, long long steps);

// The thread counts of a list option (fem_bench --threads, fem_lessons multigrid
// --cost-threads): each checked as --threads is (UsageError; a warning on stderr above the
// hardware threads), a repeated one kept once; when the option is empty, 1 and OpenMP's count.
std::vector<int> thread_counts_from_args(const ArgParser& args, const std::string& name);

// main()'s error handling, written once: returns body()'s exit status; a UsageError prints
// "<program>: <why> (see <program> --help)" and returns 2, any other exception
// "<program>: error: <why>" and returns 1. Before body(), OMP_NUM_THREADS's form is checked
// (thread_environment_count): a value that is not a count is a UsageError before any OpenMP call.
int run_program(const std::string& program, const std::function<int()>& body);

// A relative mesh path is looked up from the working directory, then from the repository.
std::string resolve_mesh_path(const std::string& path);

// --readme FILE of the programs that generate docs: replaces the text between the lines
// <!-- NAME:begin --> and <!-- NAME:end --> of the file. Throws std::runtime_error when the
// file cannot be read or has no such markers.
void write_between_markers(const std::string& path, const std::string& name,
                           const std::string& text);
// The same checks alone, before the work whose text goes there (a lesson's measurement).
void check_markers(const std::string& path, const std::string& name);
// The text between the markers, as write_between_markers wrote it (from the newline after the
// begin marker); throws as it does.
std::string read_between_markers(const std::string& path, const std::string& name);

}  // namespace fem
