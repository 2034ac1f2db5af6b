#include "common/json.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "common/atomic_file.hpp"

namespace fem {

namespace {

// A number as the hand-written JSON had it: ten significant digits (0.304167, not
// nlohmann's shortest round trip 0.30416699999999997), which no measurement here reaches.
std::string plain(const Json& v) {
  if (v.is_number_float() && std::isfinite(v.get<double>())) {
    std::ostringstream out;
    out << std::setprecision(10) << v.get<double>();
    return out.str();
  }
  return v.dump(-1, ' ', false, Json::error_handler_t::replace);
}

void write(std::string& out, const Json& v, int depth) {
  const bool flat =
      std::none_of(v.begin(), v.end(), [](const Json& e) { return e.is_structured(); });
  if (!v.is_structured() || v.empty() || flat) {
    if (!v.is_structured()) {
      out += plain(v);
      return;
    }
    // One line, with the spaces nlohmann's compact form leaves out.
    out += v.is_object() ? "{" : "[";
    bool first = true;
    for (auto it = v.begin(); it != v.end(); ++it, first = false)
      out += (first ? "" : ", ") + (v.is_object() ? plain(it.key()) + ": " : "") + plain(*it);
    out += v.is_object() ? "}" : "]";
    return;
  }
  const std::string indent(2 * (depth + 1), ' ');
  out += v.is_object() ? "{\n" : "[\n";
  bool first = true;
  for (auto it = v.begin(); it != v.end(); ++it, first = false) {
    out += (first ? "" : ",\n") + indent + (v.is_object() ? plain(it.key()) + ": " : "");
    write(out, *it, depth + 1);
  }
  out += "\n" + std::string(2 * depth, ' ') + (v.is_object() ? "}" : "]");
}

}  // namespace

std::string json_text(const Json& value) {
  std::string out;
  write(out, value, 0);
  return out;
}

void write_json_file(const std::string& path, const Json& value) {
  write_file_atomically(path, json_text(value) + "\n");
}

}  // namespace fem
