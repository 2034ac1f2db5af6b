// The one JSON helper the result writers (fem_bench, fem_viewer's report) share.
#pragma once

#include <string>

namespace fem {

// s as a JSON string literal: quotes and backslashes escaped (control characters never occur
// in what we write: compiler names, flags, CPU and renderer names, file paths).
inline std::string json_string(const std::string& s) {
  std::string out = "\"";
  for (const char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

}  // namespace fem
