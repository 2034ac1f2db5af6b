#include "common/cli.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>

#if __has_include(<unistd.h>)
#include <fcntl.h>
#include <unistd.h>
#endif

#include "common/atomic_file.hpp"
#include "common/build_info.hpp"
#include "common/threads.hpp"

namespace fem {
namespace {

std::string format_number(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

}  // namespace

ArgParser::ArgParser(std::string program, std::string summary)
    : program_(std::move(program)), summary_(std::move(summary)) {}

void ArgParser::option(const std::string& name, const std::string& value_name,
                       const std::string& help, const std::string& default_value) {
  order_.push_back(name);
  options_[name] = {value_name, help, default_value, false, false};
}

void ArgParser::flag(const std::string& name, const std::string& help) {
  order_.push_back(name);
  options_[name] = {"", help, "", true, false};
}

bool ArgParser::parse(int argc, const char* const* argv) {
  for (int i = 1; i < argc; ++i) {
    std::string arg = argv[i];
    if (arg == "--help" || arg == "-h") {
      std::cout << help();
      return false;
    }
    std::string value;
    bool has_inline_value = false;
    if (const auto eq = arg.find('='); arg.rfind("--", 0) == 0 && eq != std::string::npos) {
      value = arg.substr(eq + 1);
      arg = arg.substr(0, eq);
      has_inline_value = true;
    }
    if (arg.rfind("--", 0) != 0) throw UsageError("unexpected argument '" + arg + "'");
    const auto it = options_.find(arg.substr(2));
    if (it == options_.end()) throw UsageError("unknown option '" + arg + "'");
    Option& opt = it->second;
    opt.set = true;
    if (opt.is_flag) {
      if (has_inline_value) throw UsageError("option '" + arg + "' takes no value");
      continue;
    }
    if (!has_inline_value) {
      if (i + 1 >= argc) throw UsageError("option '" + arg + "' needs a value");
      value = argv[++i];
    }
    opt.value = value;
  }
  return true;
}

namespace {

// std::stoi or std::stod on the whole of s, without their exceptions.
template <class Number, class Convert>
std::optional<Number> parse_number(const std::string& s, Convert convert) {
  std::size_t used = 0;
  Number v{};
  try {
    v = convert(s, &used);
  } catch (const std::exception&) {
    return std::nullopt;
  }
  if (used == 0 || used != s.size()) return std::nullopt;
  return v;
}

}  // namespace

std::optional<int> parse_int(const std::string& s) {
  return parse_number<int>(
      s, [](const std::string& t, std::size_t* used) { return std::stoi(t, used); });
}

std::optional<double> parse_double(const std::string& s) {
  return parse_number<double>(
      s, [](const std::string& t, std::size_t* used) { return std::stod(t, used); });
}

const std::string& ArgParser::get(const std::string& name) const { return options_.at(name).value; }

const std::string& ArgParser::get_nonempty(const std::string& name) const {
  const Option& o = options_.at(name);
  if (o.set && o.value.empty())
    throw UsageError("--" + name + ": an empty value names no " + o.value_name +
                     ": give one, or leave the option out");
  return o.value;
}

double ArgParser::get_double(const std::string& name) const {
  const std::optional<double> v = parse_double(get(name));
  if (v && std::isfinite(*v)) return *v;
  // A number too small or too large for a double (1e-320, 1e400) is a number: say so, rather
  // than that it is not a finite one.
  errno = 0;
  const double magnitude = std::strtod(get(name).c_str(), nullptr);
  if (!v && errno == ERANGE)
    throw UsageError("--" + name + " " + get(name) + " is out of a double's range (" +
                     (std::abs(magnitude) < 1.0 ? "below 2.2e-308" : "above 1.8e+308") + ")");
  throw UsageError("--" + name + " expects a finite number, got '" + get(name) + "'");
}

int ArgParser::get_int(const std::string& name) const {
  const std::optional<int> v = parse_int(get(name));
  if (v) return *v;
  // An integer too large for an int (--every 1000000000000) is an integer: say so.
  const std::optional<double> number = parse_double(get(name));
  if (number && *number == std::floor(*number) && std::abs(*number) > 2147483647.0)
    throw UsageError("--" + name + " " + get(name) + " is out of range (at most 2147483647)");
  throw UsageError("--" + name + " expects an integer, got '" + get(name) + "'");
}

bool ArgParser::has_flag(const std::string& name) const { return options_.at(name).set; }

std::vector<std::string> ArgParser::get_list(const std::string& name) const {
  std::vector<std::string> items;
  std::stringstream list(get(name));
  for (std::string item; std::getline(list, item, ',');)
    if (!item.empty()) items.push_back(item);
  return items;
}

std::vector<int> ArgParser::get_int_list(const std::string& name) const {
  std::vector<int> out;
  for (const std::string& item : get_list(name)) {
    const std::optional<int> v = parse_int(item);
    if (!v)
      throw UsageError("--" + name + " expects integers separated by commas, got '" + get(name) +
                       "'");
    if (std::find(out.begin(), out.end(), *v) == out.end()) out.push_back(*v);
  }
  return out;
}

std::string ArgParser::help() const {
  std::ostringstream out;
  out << "usage: " << program_ << " [options]\n\n" << summary_ << "\n\noptions:\n";
  for (const auto& name : order_) {
    const Option& o = options_.at(name);
    std::string left = "  --" + name + (o.is_flag ? "" : " " + o.value_name);
    out << left << std::string(left.size() < 26 ? 26 - left.size() : 1, ' ') << o.help;
    if (!o.is_flag && !o.value.empty()) out << " (default: " << o.value << ")";
    out << "\n";
  }
  out << "  --help                  print this help and exit\n";
  return out.str();
}

void add_scene_options(ArgParser& args, const std::string& default_mesh) {
  const Material m;
  const RayleighDamping d;
  const Scene s;
  args.option("scene", "NAME", "built-in scene: cantilever or sliding", "cantilever");
  args.option("mesh", "FILE", "gmsh .msh file with linear tetrahedra", default_mesh);
  args.option("E", "PA", "Young's modulus, > 0", format_number(m.youngs_modulus));
  args.option("nu", "RATIO", "Poisson's ratio, in (-1, 0.5)", format_number(m.poisson_ratio));
  args.option("rho", "KG_M3", "density, > 0", format_number(m.density));
  args.option("dt", "SECONDS", "time step, > 0", format_number(s.dt));
  args.option("alpha", "1/S", "Rayleigh mass damping, >= 0", format_number(d.alpha));
  args.option("beta", "S", "Rayleigh stiffness damping, >= 0", format_number(d.beta));
}

std::string resolve_mesh_path(const std::string& path) {
  namespace fs = std::filesystem;
  // An empty path stays empty (load_mesh refuses it): joined to the source folder it named
  // the folder itself.
  if (path.empty()) return path;
  if (fs::path(path).is_relative() && !fs::exists(path) &&
      fs::exists(fs::path(source_dir()) / path))
    return (fs::path(source_dir()) / path).string();
  return path;
}

Scene scene_from_args(const ArgParser& args) {
  Material m;
  m.youngs_modulus = args.get_double("E");
  m.poisson_ratio = args.get_double("nu");
  m.density = args.get_double("rho");
  const double dt = args.get_double("dt");
  const double alpha = args.get_double("alpha"), beta = args.get_double("beta");
  // Check the numbers before loading a mesh, so a typo fails at once.
  Scene probe;
  probe.material = m;
  probe.dt = dt;
  probe.damping = {alpha, beta};
  try {
    validate(probe);
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  const std::string& name = args.get("scene");
  bool known = false;
  for (const auto& s : scene_names()) known = known || s == name;
  if (!known) throw UsageError("unknown scene '" + name + "' (known: cantilever, sliding)");

  TetMesh mesh = load_mesh(resolve_mesh_path(args.get("mesh")));
  if (mesh.reoriented_tets > 0)
    std::cerr << "note: " << mesh.file << ": " << mesh.reoriented_tets
              << " inverted tetrahedra were reoriented on load\n";
  if (mesh.dropped_nodes > 0)
    std::cerr << "note: " << mesh.file << ": " << mesh.dropped_nodes
              << " nodes used by no tetrahedron were dropped\n";
  Scene scene = make_scene(name, std::move(mesh), m);
  scene.dt = dt;
  scene.damping = {alpha, beta};
  validate(scene);
  return scene;
}

void add_solver_options(ArgParser& args) {
  const SolverSettings s;
  args.option("tol", "REL", "CG relative residual tolerance, in (0, 1)",
              format_number(s.tolerance));
  args.option("max-iters", "N", "CG iteration cap, > 0", std::to_string(s.max_iterations));
}

SolverSettings solver_from_args(const ArgParser& args) {
  SolverSettings s;
  s.tolerance = args.get_double("tol");
  s.max_iterations = args.get_int("max-iters");
  if (!(s.tolerance > 0.0 && s.tolerance < 1.0)) throw UsageError("--tol must lie in (0, 1)");
  if (s.max_iterations <= 0) throw UsageError("--max-iters must be positive");
  return s;
}

void add_thread_option(ArgParser& args) {
  args.option("threads", "N",
              "threads of the parallel chapters, 09 on: the count every step runs on (default: "
              "OMP_NUM_THREADS, else the steppers choose: one thread below 20000 nodes, else "
              "all " +
                  std::to_string(hardware_threads()) + ", or one while that is faster)",
              "");
}

void apply_thread_environment() {
  try {
    if (const std::string warning = check_thread_environment(); !warning.empty())
      std::cerr << "warning: " << warning << "\n";
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
}

std::vector<int> thread_counts_from_args(const ArgParser& args, const std::string& name) {
  std::vector<int> counts = args.get_int_list(name);
  if (counts.empty() && args.given(name))  // --threads "" or ",": a list that names none
    throw UsageError("--" + name + " '" + args.get(name) + "' names no thread count");
  if (counts.empty()) {
    apply_thread_environment();  // OMP_NUM_THREADS, held to the rule of --threads
    counts = max_threads() > 1 ? std::vector<int>{1, max_threads()} : std::vector<int>{1};
  }
  for (const int n : counts) {
    try {
      if (const std::string warning = check_thread_count(n); !warning.empty())
        std::cerr << "warning: --" << name << " " << n << ": " << warning << "\n";
    } catch (const std::invalid_argument& e) {
      throw UsageError("--" + name + " " + std::to_string(n) + ": " + e.what());
    }
  }
  return counts;
}

int threads_from_args(const ArgParser& args) {
  if (args.given("threads")) {
    // An empty value is a mistake like any other, not "not given" (--threads "$N" unset).
    const int n = args.get_int("threads");
    try {
      if (const std::string warning = check_thread_count(n); !warning.empty())
        std::cerr << "warning: --threads " << n << ": " << warning << "\n";
      set_threads(n);
    } catch (const std::invalid_argument& e) {
      throw UsageError(std::string("--threads: ") + e.what());
    }
    set_thread_count_asked(true);
  } else {
    apply_thread_environment();
    set_thread_count_asked(thread_environment_count() > 0);
  }
  return max_threads();
}

namespace {

// The file's text and where the text between its markers <!-- NAME:begin/end --> starts and
// ends; throws std::runtime_error naming what is missing.
struct MarkedDoc {
  std::string text;
  std::size_t from = 0, to = 0;
};

MarkedDoc read_marked(const std::string& path, const std::string& name) {
  if (std::filesystem::is_directory(path))
    throw std::runtime_error("'" + path + "' is a directory, not a file with markers");
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read '" + path + "'");
  std::stringstream buffer;
  buffer << in.rdbuf();
  MarkedDoc doc{buffer.str()};
  const std::string begin = "<!-- " + name + ":begin -->", end = "<!-- " + name + ":end -->";
  const auto b = doc.text.find(begin), e = doc.text.find(end);
  if (b == std::string::npos || e == std::string::npos || e < b)
    throw std::runtime_error("'" + path + "' has no markers " + begin + " ... " + end);
  doc.from = b + begin.size();
  doc.to = e;
  return doc;
}

}  // namespace

void check_markers(const std::string& path, const std::string& name) { read_marked(path, name); }

std::string read_between_markers(const std::string& path, const std::string& name) {
  const MarkedDoc doc = read_marked(path, name);
  return doc.text.substr(doc.from, doc.to - doc.from);
}

void write_between_markers(const std::string& path, const std::string& name,
                           const std::string& text) {
  MarkedDoc doc = read_marked(path, name);
  doc.text.replace(doc.from, doc.to - doc.from, "\n" + text);
  write_file_atomically(path, doc.text);
}

void announce_long_run(const std::string& program, double seconds_per_step, long long steps) {
  const double seconds = seconds_per_step * static_cast<double>(steps);
  if (!(seconds > 60.0)) return;
  std::ostringstream about;
  about.precision(seconds < 600.0 ? 1 : 0);
  about << std::fixed;
  if (seconds < 3600.0)
    about << seconds / 60.0 << " min";
  else
    about << seconds / 3600.0 << " h";
  std::cout << program << ": this run will take about " << about.str() << " (" << steps
            << " steps at " << format_number(seconds_per_step) << " s each, from the first)"
            << std::endl;
}

namespace {

// OMP_NUM_THREADS's form is checked first, by every program, --threads given or not: the OpenMP
// runtime reads the variable at its first call whatever the program asks, and LLVM's aborts on
// a value that is not a count (common/threads.hpp, thread_environment_count).
void check_thread_environment_form() {
  try {
    thread_environment_count();
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
}

// A standard stream the caller closed (`fem_sim >&-`) is held by /dev/null opened read-only:
// closed, its number is the lowest free one, so the first file the program opens (a frame's
// temporary file) would take it and receive the printout. Read-only, every write to it still
// fails as it did closed, and run_program says so.
void hold_closed_standard_streams() {
#if __has_include(<unistd.h>)
  for (const int fd : {0, 1, 2}) {
    if (::fcntl(fd, F_GETFD) != -1 || errno != EBADF) continue;
    const int held = ::open("/dev/null", O_RDONLY);  // the lowest free number: fd itself
    if (held != -1 && held != fd) {
      ::dup2(held, fd);
      ::close(held);
    }
  }
#endif
}

int run_body(const std::string& program, const std::function<int()>& body) {
  try {
    check_thread_environment_form();
    return body();
  } catch (const UsageError& e) {
    std::cerr << program << ": " << e.what() << " (see " << program << " --help)\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << program << ": error: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace

int run_program(const std::string& program, const std::function<int()>& body) {
  hold_closed_standard_streams();
  const int status = run_body(program, body);
  // What a program prints may be its result (fem_sim --watch, a lesson's table): lost to a full
  // disk or a closed stream, it is a failure a script must see, not an exit status of 0.
  if (!(std::cout << std::flush)) {
    std::cerr << program
              << ": error: cannot write the standard output (a full disk, or a "
                 "closed stream): what the run printed is lost\n";
    return status != 0 ? status : 1;
  }
  return status;
}

}  // namespace fem
