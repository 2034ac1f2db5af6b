// The JSON the programs write (bench.json, the lessons' records, the machine record): built as
// nlohmann::json values (Debian nlohmann-json3-dev), so that quoting, escaping and commas are
// the library's, not ours.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

namespace fem {

// An object keeps its keys in the order they were added: a reader of bench.json finds the run
// before its tables, as the schema (README.md) lists them.
using Json = nlohmann::ordered_json;

// s as a JSON string literal: quotes, backslashes and control characters escaped (a lesson's
// table is several lines of Markdown); bytes that are not UTF-8 become U+FFFD.
inline std::string json_string(const std::string& s) {
  return Json(s).dump(-1, ' ', false, Json::error_handler_t::replace);
}

// `value` as text a reader can scan and a diff can show: numbers to ten significant digits, an
// object or array of plain values on one line ({"forces": 0.1, "dfdx": 0.2, ...}), any other
// one member per line, indented.
std::string json_text(const Json& value);

// json_text(value) written to `path` with a final newline, whole or not at all
// (write_file_atomically, common/atomic_file.hpp); throws its WriteError.
void write_json_file(const std::string& path, const Json& value);

}  // namespace fem
