#include "common/msh_check.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <vector>

#include "common/mesh.hpp"

namespace fem {
namespace {

using Count = std::uint64_t;

// The fewest bytes a record takes in an ASCII file, by which a header's count
// is checked against the bytes left: a node is "1 0 0 0\n" (MSH 2.2) or "1\n"
// and "0 0 0\n" (MSH 4.1), an element at least "1 1\n", an entity or a block
// header at least "0 1 0 0\n".
constexpr Count kNodeBytes = 8, kElementBytes = 4, kHeaderBytes = 8;

[[noreturn]] void fail_file(const std::string& file, const std::string& problem) {
  throw MeshError("mesh '" + file + "': " + problem);
}

// Reads the file line by line, counting the bytes read so that a header's count
// can be held against the bytes left, and the lines, so that a message can
// point into the file.
class MshReader {
 public:
  MshReader(const std::string& path, Count size) : path_(path), size_(size), in_(path) {
    if (!in_) fail("cannot open the file (missing or unreadable)");
  }

  // The next line without its line end ("\r\n" too), or false at the end of the
  // file.
  bool next(std::string& line) {
    if (!std::getline(in_, line)) return false;
    read_ += line.size() + 1;
    ++line_number_;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    return true;
  }

  // Whether the last line had no line end: the file's last, cut inside a
  // section.
  bool at_cut_end() const { return in_.eof(); }
  Count bytes_left() const { return read_ < size_ ? size_ - read_ : 0; }
  [[noreturn]] void fail(const std::string& problem) const { fail_file(path_, problem); }
  std::string at() const { return "line " + std::to_string(line_number_); }

 private:
  std::string path_;
  Count size_, read_ = 0, line_number_ = 0;
  std::ifstream in_;
};

// A section's records as its header declares them, for the messages of a cut or
// short section.
struct Records {
  std::string section;  // "Nodes"
  std::string noun;     // "nodes"
  Count declared = 0;
};

// The next record line of a section: the file's end or a '$' line there means
// the section holds fewer records than its header declares.
void next_record(MshReader& r, const Records& s, Count done, std::string& line) {
  const std::string progress =
      std::to_string(done) + " of its " + std::to_string(s.declared) + " " + s.noun + ")";
  if (!r.next(line) || r.at_cut_end())
    r.fail("the file ends inside section $" + s.section + " (after " + progress);
  if (!line.empty() && line[0] == '$')
    r.fail(r.at() + ": section $" + s.section + " ends early (" + line + " after " + progress);
}

// The first n whitespace-separated integers of a line, or a message naming the
// line.
template <std::size_t n>
std::array<std::int64_t, n> integers(const MshReader& r, const std::string& line,
                                     const std::string& what) {
  std::array<std::int64_t, n> out{};
  const char* p = line.data();
  const char* const end = p + line.size();
  for (auto& value : out) {
    while (p < end && (*p == ' ' || *p == '\t')) ++p;
    const auto [next, error] = std::from_chars(p, end, value);
    // The whole word is the number: "1e9" is not the count 1.
    const bool whole = next == end || *next == ' ' || *next == '\t';
    if (error != std::errc() || !whole) r.fail(r.at() + ": '" + line + "' is not " + what);
    p = next;
  }
  return out;
}

// The whitespace-separated words of a line (a node's tag and coordinates, an element's nodes).
std::size_t words(const std::string& line) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < line.size(); ++i)
    n += line[i] != ' ' && line[i] != '\t' && (i == 0 || line[i - 1] == ' ' || line[i - 1] == '\t');
  return n;
}

// The nodes of gmsh's element types up to 19 (points, lines, triangles, quadrangles,
// tetrahedra, hexahedra, prisms, pyramids, first and second order); 0 for another type, whose
// lines are then not counted.
std::size_t nodes_of_type(std::int64_t type) {
  static constexpr std::array<std::size_t, 20> kNodes = {0, 2,  3,  4,  4,  8, 6, 5,  3,  6,
                                                         9, 10, 27, 18, 14, 1, 8, 20, 15, 13};
  return type > 0 && type < static_cast<std::int64_t>(kNodes.size()) ? kNodes[type] : 0;
}

// An element line holds exactly its type's nodes after `before` words: a node missing or too
// many shifts gmsh's reading of every later line (a tetrahedron one node short was read as a
// prism).
void check_element_words(const MshReader& r, const std::string& line, std::int64_t type,
                         std::size_t before) {
  const std::size_t nodes = nodes_of_type(type);
  if (nodes > 0 && words(line) != before + nodes)
    r.fail(r.at() + ": element '" + line + "' of gmsh type " + std::to_string(type) + " lists " +
           std::to_string(words(line) - std::min(words(line), before)) + " nodes, not its " +
           std::to_string(nodes));
}

// A node's tag: gmsh numbers nodes from 1.
Count node_tag(const MshReader& r, const std::string& line, const std::string& what) {
  const std::int64_t tag = integers<1>(r, line, what)[0];
  if (tag < 1)
    r.fail(r.at() + ": node tag " + std::to_string(tag) + " (gmsh numbers nodes from 1)");
  return static_cast<Count>(tag);
}

// A count from a header, refused when negative or when the bytes left cannot
// hold that many records: checked before anything is sized by it.
Count checked_count(const MshReader& r, std::int64_t count, const Records& s, Count min_bytes) {
  if (count < 0) r.fail(r.at() + ": section $" + s.section + " declares a negative count");
  const Count fits = r.bytes_left() / min_bytes;
  if (static_cast<Count>(count) > fits)
    r.fail("its $" + s.section + " section declares " + std::to_string(count) + " " + s.noun +
           ", more than the file can hold (" + std::to_string(r.bytes_left()) +
           " bytes follow the count: room for at most " + std::to_string(fits) + " at " +
           std::to_string(min_bytes) + " bytes each): the file ends inside section $" + s.section +
           ", or the header is corrupt");
  return static_cast<Count>(count);
}

void expect_end(MshReader& r, const std::string& section) {
  std::string line;
  if (!r.next(line))
    r.fail("the file ends inside section $" + section + " (no $End" + section + ")");
  if (line != "$End" + section)
    r.fail(r.at() + ": '" + line + "' where $End" + section +
           " should close the section: it holds more than its header declares");
}

// Skips a section this check does not read, up to its end line.
void skip_section(MshReader& r, const std::string& section) {
  std::string line;
  while (r.next(line))
    if (line == "$End" + section) return;
  r.fail("the file ends inside section $" + section + " (no $End" + section + ")");
}

// A section's header line of n counts.
template <std::size_t n>
std::array<std::int64_t, n> header(MshReader& r, const std::string& section) {
  std::string line;
  if (!r.next(line)) r.fail("the file ends inside section $" + section + " (before its header)");
  return integers<n>(r, line, "the section's header (" + std::to_string(n) + " integers)");
}

void scan_nodes_22(MshReader& r, std::vector<Count>& tags) {
  Records s{"Nodes", "nodes", 0};
  s.declared = checked_count(r, header<1>(r, s.section)[0], s, kNodeBytes);
  tags.reserve(s.declared);
  std::string line;
  for (Count i = 0; i < s.declared; ++i) {
    next_record(r, s, i, line);
    if (words(line) < 4) r.fail(r.at() + ": '" + line + "' is not a node (tag x y z)");
    tags.push_back(node_tag(r, line, "a node (tag x y z)"));
  }
  expect_end(r, "Nodes");
}

// One entity block of MSH 4.1's $Nodes: its tags, one a line, then as many
// coordinate lines.
void scan_node_block_41(MshReader& r, const Records& s, std::vector<Count>& tags) {
  std::string line;
  next_record(r, s, tags.size(), line);
  const Count left = s.declared - tags.size();
  const auto block = integers<4>(r, line, "a node block's header (dim tag parametric count)");
  if (block[3] < 0 || static_cast<Count>(block[3]) > left)
    r.fail(r.at() + ": a node block of " + std::to_string(block[3]) + " nodes where the header's " +
           std::to_string(s.declared) + " leave " + std::to_string(left));
  const Count done = tags.size(), in_block = static_cast<Count>(block[3]);
  for (Count i = 0; i < in_block; ++i) {
    next_record(r, s, done + i, line);
    tags.push_back(node_tag(r, line, "a node tag"));
  }
  for (Count i = 0; i < in_block; ++i) {
    next_record(r, s, done + i, line);
    if (words(line) < 3) r.fail(r.at() + ": '" + line + "' is not a node's x y z");
  }
}

void scan_nodes_41(MshReader& r, std::vector<Count>& tags) {
  Records s{"Nodes", "nodes", 0};
  const auto head = header<4>(r, s.section);
  const Count blocks = checked_count(r, head[0], {"Nodes", "entity blocks"}, kHeaderBytes);
  s.declared = checked_count(r, head[1], s, kNodeBytes);
  tags.reserve(s.declared);
  for (Count b = 0; b < blocks; ++b) scan_node_block_41(r, s, tags);
  if (tags.size() != s.declared)
    r.fail("its $Nodes section declares " + std::to_string(s.declared) +
           " nodes and its blocks hold " + std::to_string(tags.size()));
  expect_end(r, "Nodes");
}

void scan_elements_22(MshReader& r) {
  Records s{"Elements", "elements", 0};
  s.declared = checked_count(r, header<1>(r, s.section)[0], s, kElementBytes);
  std::string line;
  for (Count i = 0; i < s.declared; ++i) {
    next_record(r, s, i, line);
    const auto head = integers<3>(r, line, "an element (tag type tag-count tags nodes)");
    check_element_words(r, line, head[1],
                        3 + static_cast<std::size_t>(std::max<std::int64_t>(head[2], 0)));
  }
  expect_end(r, "Elements");
}

void scan_elements_41(MshReader& r) {
  Records s{"Elements", "elements", 0};
  const auto head = header<4>(r, s.section);
  const Count blocks = checked_count(r, head[0], {"Elements", "entity blocks"}, kHeaderBytes);
  s.declared = checked_count(r, head[1], s, kElementBytes);
  Count done = 0;
  std::string line;
  for (Count b = 0; b < blocks; ++b) {
    next_record(r, s, done, line);
    const auto block = integers<4>(r, line, "an element block's header (dim tag type count)");
    if (block[3] < 0 || static_cast<Count>(block[3]) > s.declared - done)
      r.fail(r.at() + ": an element block of " + std::to_string(block[3]) +
             " elements where the header's " + std::to_string(s.declared) + " leave " +
             std::to_string(s.declared - done));
    const Count end = done + static_cast<Count>(block[3]);
    for (; done < end; ++done) {
      next_record(r, s, done, line);
      check_element_words(r, line, block[2], 1);
    }
  }
  expect_end(r, "Elements");
}

// MSH 4.1's $Entities: the four counts held against the file's size (gmsh reads
// that many).
void scan_entities_41(MshReader& r) {
  const Records s{"Entities", "entities", 0};
  for (const std::int64_t count : header<4>(r, s.section)) checked_count(r, count, s, kHeaderBytes);
  skip_section(r, "Entities");
}

// A line of one count that the bytes left must hold at `min_bytes` a record.
Count count_line(MshReader& r, const Records& s, Count min_bytes) {
  return checked_count(r, header<1>(r, s.section)[0], s, min_bytes);
}

// $NodeData, $ElementData, $ElementNodeData: tags (strings, reals, integers,
// each a count and as many lines), then one line per entity. gmsh sizes its
// arrays by the integer tags (the entities, their components), so they are held
// against the bytes left too.
void scan_data_section(MshReader& r, const std::string& section) {
  std::string line;
  for (const char* kind : {"string tags", "real tags"}) {
    const Count n = count_line(r, {section, kind}, 2);
    for (Count i = 0; i < n; ++i) next_record(r, {section, kind, n}, i, line);
  }
  const Records ints{section, "integer tags"};
  const Count n = count_line(r, ints, 2);
  Count components = 1;
  for (Count i = 0; i < n; ++i) {
    next_record(r, {section, "integer tags", n}, i, line);
    const std::int64_t value = integers<1>(r, line, "an integer tag")[0];
    if (i == 1) components = checked_count(r, value, {section, "components"}, 2);
    if (i == 2) checked_count(r, value, {section, "entries"}, 2 * std::max<Count>(components, 1));
  }
  skip_section(r, section);
}

// The version from $MeshFormat: 2 (2.x) or 4 (4.1), ASCII only.
int read_format(MshReader& r) {
  std::string line;
  if (!r.next(line) || line != "$MeshFormat")
    r.fail(line.rfind("\xEF\xBB\xBF", 0) == 0
               ? "it starts with a byte-order mark before $MeshFormat: save it without one"
               : "not a gmsh .msh file (its first line is not $MeshFormat)");
  if (!r.next(line)) r.fail("the file ends inside section $MeshFormat");
  const std::string version = line.substr(0, line.find(' '));
  const auto words = line.substr(version.size());
  const auto binary = integers<1>(r, words, "'version file-type data-size'")[0];
  if (version.rfind("2.", 0) != 0 && version != "4.1")
    r.fail("MSH version " + version +
           ": the programs read MSH 4.1 and 2.2 (in gmsh: " + "Mesh.MshFileVersion = 4.1)");
  if (binary != 0)
    r.fail(
        "a binary .msh file: the programs read ASCII files, whose counts "
        "they check before "
        "reading (in gmsh: Mesh.Binary = 0)");
  expect_end(r, "MeshFormat");
  return version == "4.1" ? 4 : 2;
}

// The path names a regular file: an empty path, a directory or a device is
// refused by name.
Count checked_file_size(const std::string& path) {
  namespace fs = std::filesystem;
  if (path.empty()) fail_file(path, "an empty path names no file");
  std::error_code error;
  const auto status = fs::status(path, error);
  if (!fs::exists(status)) fail_file(path, "cannot open the file (missing or unreadable)");
  if (fs::is_directory(status)) fail_file(path, "is a directory, not a mesh file");
  if (!fs::is_regular_file(status)) fail_file(path, "is not a regular file");
  const Count size = fs::file_size(path);
  if (size == 0) fail_file(path, "the file is empty");
  return size;
}

void refuse_duplicate_tags(const MshReader& r, std::vector<Count>& tags) {
  std::sort(tags.begin(), tags.end());
  const auto twice = std::adjacent_find(tags.begin(), tags.end());
  if (twice != tags.end())
    r.fail("duplicate node tag " + std::to_string(*twice) +
           ": the file defines that node twice (gmsh would keep the last and "
           "move the node)");
}

std::string missing_section(const std::string& section, const std::string& last) {
  if (last.empty()) return "the file has no $" + section + " section";
  return "the file ends after section $" + last + ", with no $" + section + " section";
}

}  // namespace

void check_msh_file(const std::string& path) {
  MshReader r(path, checked_file_size(path));
  const int version = read_format(r);
  std::vector<Count> tags;
  bool nodes = false, elements = false;
  std::string line, last = "MeshFormat";
  while (r.next(line)) {
    if (line.empty() || line[0] != '$') continue;  // gmsh skips lines between sections too
    const std::string section = line.substr(1);
    if (section.rfind("End", 0) == 0) r.fail(r.at() + ": " + line + " without its start");
    if (section == "Nodes") {
      if (nodes) r.fail(r.at() + ": a second $Nodes section");
      version == 4 ? scan_nodes_41(r, tags) : scan_nodes_22(r, tags);
      nodes = true;
    } else if (section == "Elements") {
      // A second one adds its elements to the first's (gmsh reads both): a body
      // stiffer and heavier than the file's first section says.
      if (elements) r.fail(r.at() + ": a second $Elements section");
      version == 4 ? scan_elements_41(r) : scan_elements_22(r);
      elements = true;
    } else if (section == "Entities" && version == 4) {
      scan_entities_41(r);
    } else if (section == "PhysicalNames") {
      count_line(r, {section, "names"}, 6);  // "1 1 ""\n" at least
      skip_section(r, section);
    } else if (section == "NodeData" || section == "ElementData" || section == "ElementNodeData") {
      scan_data_section(r, section);
    } else {
      skip_section(r, section);
    }
    last = section;
  }
  if (!nodes) r.fail(missing_section("Nodes", last));
  if (!elements) r.fail(missing_section("Elements", last));
  refuse_duplicate_tags(r, tags);
}

}  // namespace fem
