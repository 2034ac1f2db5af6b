// The one JSON helper the result writers (fem_bench, fem_viewer's report) share.
#pragma once

#include <string>

namespace fem {

// s as a JSON string literal: quotes, backslashes and control characters escaped (a lesson's
// table is several lines of Markdown).
inline std::string json_string(const std::string& s) {
  std::string out = "\"";
  for (const char c : s) {
    if (c == '\n') {
      out += "\\n";
    } else if (static_cast<unsigned char>(c) < 0x20) {
      const char* hex = "0123456789abcdef";
      out += std::string("\\u00") + hex[(c >> 4) & 0xf] + hex[c & 0xf];
    } else {
      if (c == '"' || c == '\\') out += '\\';
      out += c;
    }
  }
  return out + "\"";
}

}  // namespace fem
