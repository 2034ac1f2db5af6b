// The sections are named as gmsh's documentation names them ("MSH file format", gmsh reference
// manual): $MeshFormat, $PhysicalNames, $Entities, $Nodes, $Elements, $NodeData and the other
// data sections; every other section is skipped to its end line, as gmsh skips it.
#include "common/msh_read.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
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
  // file. A CR inside a line means lines that end in CR alone (classic Mac OS), which
  // reads as one line (the first line of any other file is refused as not a mesh).
  bool next(std::string& line) {
    if (!std::getline(in_, line)) return false;
    read_ += line.size() + 1;
    ++line_number_;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.find('\r') != std::string::npos &&
        (line_number_ > 1 || line.rfind("$MeshFormat\r", 0) == 0))
      fail(at() +
           " holds a carriage return (CR) inside it: the file's lines end in CR alone "
           "(classic Mac OS line ends); save it with LF or CRLF line ends");
    return true;
  }

  // Whether the last line had no line end: the file's last, cut inside a
  // section.
  bool at_cut_end() const { return in_.eof(); }
  Count bytes_left() const { return read_ < size_ ? size_ - read_ : 0; }
  Count line_number() const { return line_number_; }
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

// What the file holds, as read: nodes and elements with their lines, for the messages.
struct Node {
  Count tag, line;
  std::array<double, 3> x;
};
struct Tet {
  std::int64_t entity, order, tag;  // order: MSH 2.2 the element tag, MSH 4.1 the position
  std::array<int, 4> nodes;
};
struct Contents {
  std::vector<Node> nodes;  // sorted by tag at the end of $Nodes
  std::vector<Tet> tets;
  std::vector<std::pair<std::int64_t, Count>> element_tags;  // tag, line
  std::map<int, std::pair<std::string, std::size_t>> other_volume;
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

// The whitespace-separated words of a line.
std::vector<std::string> words_of(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> out;
  for (std::string word; in >> word;) out.push_back(word);
  return out;
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

// A word that must be an integer (an element's tag or node), or a message naming it and its line.
std::int64_t integer_word(const MshReader& r, const std::string& word, const std::string& line,
                          const std::string& what) {
  std::int64_t value = 0;
  const auto [next, error] = std::from_chars(word.data(), word.data() + word.size(), value);
  if (error != std::errc() || next != word.data() + word.size())
    r.fail(r.at() + ": '" + word + "' in '" + line + "' is not an integer (" + what + ")");
  return value;
}

// A node's x y z, the words from `first` on, parsed by strtod as gmsh's fscanf parses them;
// a word that is not wholly a number ("abc", "1.0x") is named with its line.
std::array<double, 3> coordinates(const MshReader& r, const std::string& line, std::size_t first,
                                  const std::string& what) {
  const std::vector<std::string> words = words_of(line);
  std::array<double, 3> x{};
  for (std::size_t k = 0; k < 3; ++k) {
    const std::string& word = words[first + k];
    char* end = nullptr;
    x[k] = std::strtod(word.c_str(), &end);
    if (end != word.c_str() + word.size())
      r.fail(r.at() + ": '" + word + "' in '" + line + "' is not a number (" + what + ")");
  }
  return x;
}

// gmsh's element types (MElement::getInfoMSH in gmsh 4.15), by type number: the family
// (l line, t triangle, q quadrilateral, p point; volumes in capitals: T tetrahedron,
// H hexahedron, P prism, Y pyramid; v a type whose node count varies, '-' none) and the nodes.
constexpr char kFamily[] =
    "-ltqTHPYltqTHPYpqHPYttttttlllTTTTTvvqqqqqqtttttqqqqqtttttqqqqqlllll--v-TTTTT---TTTTTltqTHP"
    "--HHHHHHHHHHHHHH------------YYYYYYYYYYYYYYYvvvvT";
constexpr std::array<int, 138> kNodes = {
    0,  2,   3,   4,   4,   8,   6,  5,  3,  6,  9,   10,  27,  18,  14,  1,   8,   20,  15,   13,
    9,  10,  12,  15,  15,  21,  4,  5,  6,  20, 35,  56,  22,  28,  0,   0,   16,  25,  36,   12,
    16, 20,  28,  36,  45,  55,  66, 49, 64, 81, 100, 121, 18,  21,  24,  27,  30,  24,  28,   32,
    36, 40,  7,   8,   9,   10,  11, 0,  0,  0,  0,   84,  120, 165, 220, 286, 0,   0,   0,    34,
    40, 46,  52,  58,  1,   1,   1,  1,  1,  1,  0,   0,   64,  125, 216, 343, 512, 729, 1000, 32,
    44, 56,  68,  80,  92,  104, 0,  0,  0,  0,  0,   0,   0,   0,   0,   0,   0,   0,   30,   55,
    91, 140, 204, 285, 385, 21,  29, 37, 45, 53, 61,  69,  1,   0,   0,   0,   0,   16};

// The nodes of an element of gmsh type `type`: refused, with the line, when gmsh defines no such
// type (gmsh itself stops at it with "Error loading") or its node count varies.
std::size_t nodes_of_type(const MshReader& r, std::int64_t type, const std::string& line) {
  const bool known = type > 0 && type < static_cast<std::int64_t>(kNodes.size());
  if (!known || kFamily[type] == '-')
    r.fail(r.at() + ": '" + line + "' has element type " + std::to_string(type) +
           ", which gmsh does not define");
  if (kFamily[type] == 'v')
    r.fail(r.at() + ": '" + line + "' has element type " + std::to_string(type) +
           " (a polygon, polyhedron or XFEM element, whose node count varies): the programs read "
           "elements of a fixed node count");
  return static_cast<std::size_t>(kNodes[static_cast<std::size_t>(type)]);
}

// gmsh's name of a volume element type ("Hexahedron 8"), or "" for another dimension.
std::string volume_name(std::int64_t type) {
  static const std::map<char, std::string> kNames = {
      {'T', "Tetrahedron"}, {'H', "Hexahedron"}, {'P', "Prism"}, {'Y', "Pyramid"}};
  const auto it = kNames.find(kFamily[type]);
  return it == kNames.end() ? "" : it->second + " " + std::to_string(kNodes[type]);
}

// An element line holds exactly its type's nodes after `before` words: a node missing or too
// many shifts gmsh's reading of every later line (a tetrahedron one node short was read as a
// prism).
void check_element_words(const MshReader& r, const std::string& line, std::int64_t type,
                         std::size_t words, std::size_t before) {
  const std::size_t nodes = nodes_of_type(r, type, line);
  if (words != before + nodes)
    r.fail(r.at() + ": element '" + line + "' of gmsh type " + std::to_string(type) + " lists " +
           std::to_string(words - std::min(words, before)) + " nodes, not its " +
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

// Skips a section this reader does not read, up to its end line.
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

// Sorts the nodes by tag (node i: the i-th smallest tag, as the programs number them) and
// refuses a tag defined twice, naming both lines: gmsh would keep the last and move the node.
void sort_nodes(const MshReader& r, std::vector<Node>& nodes) {
  std::stable_sort(nodes.begin(), nodes.end(),
                   [](const Node& a, const Node& b) { return a.tag < b.tag; });
  const auto twice = std::adjacent_find(
      nodes.begin(), nodes.end(), [](const Node& a, const Node& b) { return a.tag == b.tag; });
  if (twice != nodes.end())
    r.fail("duplicate node tag " + std::to_string(twice->tag) + " (lines " +
           std::to_string(twice->line) + " and " + std::to_string(std::next(twice)->line) +
           "): the file defines that node twice (gmsh would keep the last and move the node)");
}

void read_nodes_22(MshReader& r, std::vector<Node>& nodes) {
  Records s{"Nodes", "nodes", 0};
  s.declared = checked_count(r, header<1>(r, s.section)[0], s, kNodeBytes);
  nodes.reserve(s.declared);
  std::string line;
  for (Count i = 0; i < s.declared; ++i) {
    next_record(r, s, i, line);
    if (words_of(line).size() != 4) r.fail(r.at() + ": '" + line + "' is not a node (tag x y z)");
    const Count tag = node_tag(r, line, "a node (tag x y z)");
    nodes.push_back({tag, r.line_number(), coordinates(r, line, 1, "a node's x y z")});
  }
  expect_end(r, "Nodes");
}

// One entity block of MSH 4.1's $Nodes: "entityDim entityTag parametric numNodesInBlock", its
// node tags one a line, then as many lines "x y z" (and the parametric coordinates).
void read_node_block_41(MshReader& r, const Records& s, std::vector<Node>& nodes) {
  std::string line;
  next_record(r, s, nodes.size(), line);
  const Count left = s.declared - nodes.size();
  const auto block = integers<4>(r, line, "a node block's header (dim tag parametric count)");
  if (block[3] < 0 || static_cast<Count>(block[3]) > left)
    r.fail(r.at() + ": a node block of " + std::to_string(block[3]) + " nodes where the header's " +
           std::to_string(s.declared) + " leave " + std::to_string(left));
  const Count done = nodes.size(), in_block = static_cast<Count>(block[3]);
  for (Count i = 0; i < in_block; ++i) {
    next_record(r, s, done + i, line);
    nodes.push_back({node_tag(r, line, "a node tag"), r.line_number(), {}});
  }
  for (Count i = 0; i < in_block; ++i) {
    next_record(r, s, done + i, line);
    if (words_of(line).size() < 3) r.fail(r.at() + ": '" + line + "' is not a node's x y z");
    nodes[done + i].x = coordinates(r, line, 0, "a node's x y z");
  }
}

void read_nodes_41(MshReader& r, std::vector<Node>& nodes) {
  Records s{"Nodes", "nodes", 0};
  const auto head = header<4>(r, s.section);
  const Count blocks = checked_count(r, head[0], {"Nodes", "entity blocks"}, kHeaderBytes);
  s.declared = checked_count(r, head[1], s, kNodeBytes);
  nodes.reserve(s.declared);
  for (Count b = 0; b < blocks; ++b) read_node_block_41(r, s, nodes);
  if (nodes.size() != s.declared)
    r.fail("its $Nodes section declares " + std::to_string(s.declared) +
           " nodes and its blocks hold " + std::to_string(nodes.size()));
  expect_end(r, "Nodes");
}

// The index of the node with tag `tag` (nodes sorted by tag), or a message naming the element.
int node_index(const MshReader& r, const std::vector<Node>& nodes, std::int64_t tag,
               const std::string& element) {
  const auto it = std::lower_bound(nodes.begin(), nodes.end(), tag, [](const Node& n, auto t) {
    return static_cast<std::int64_t>(n.tag) < t;
  });
  if (tag < 1 || it == nodes.end() || static_cast<std::int64_t>(it->tag) != tag)
    r.fail(r.at() + ": element " + element + " refers to node " + std::to_string(tag) +
           ", which the $Nodes section does not define");
  return static_cast<int>(it - nodes.begin());
}

// Where an element stands: its type, its entity (gmsh's volume for a tetrahedron), its place in
// the entity's order, the word of its line where its nodes start.
struct Placed {
  std::int64_t type, entity, order;
  std::size_t first;
};

// One element, from its line's words: `words[0]` its tag, its nodes from `at.first` on. Kept
// when a linear tetrahedron, counted when another volume element; every node must be defined.
void add_element(const MshReader& r, const std::string& line, const std::vector<std::string>& words,
                 const Placed& at, Contents& c) {
  const std::int64_t type = at.type, tag = integer_word(r, words[0], line, "an element's tag");
  c.element_tags.emplace_back(tag, r.line_number());
  Tet tet{at.entity, at.order, tag, {}};
  for (std::size_t k = at.first; k < words.size(); ++k) {
    const std::int64_t node = integer_word(r, words[k], line, "an element's node");
    const int index = node_index(r, c.nodes, node, words[0]);
    if (type == 4) tet.nodes[k - at.first] = index;
  }
  if (type == 4) {
    c.tets.push_back(tet);
  } else if (!volume_name(type).empty()) {
    auto& [name, count] = c.other_volume[static_cast<int>(type)];
    name = volume_name(type);
    ++count;
  }
}

// MSH 2.2's element line: "elm-number elm-type number-of-tags <tag>... node-number-list", the
// first tag the physical group, the second the elementary entity (gmsh's volume, 0 if none).
void read_elements_22(MshReader& r, Contents& c) {
  Records s{"Elements", "elements", 0};
  s.declared = checked_count(r, header<1>(r, s.section)[0], s, kElementBytes);
  std::string line;
  for (Count i = 0; i < s.declared; ++i) {
    next_record(r, s, i, line);
    const auto head = integers<3>(r, line, "an element (tag type tag-count tags nodes)");
    const auto words = words_of(line);
    const std::size_t tags = static_cast<std::size_t>(std::max<std::int64_t>(head[2], 0));
    check_element_words(r, line, head[1], words.size(), 3 + tags);
    const std::int64_t entity = tags > 1 ? integer_word(r, words[4], line, "a tag") : 0;
    // gmsh lists a volume's tetrahedra by element tag (its MSH 2.2 reader keeps them by tag).
    add_element(r, line, words, {head[1], entity, head[0], 3 + tags}, c);
  }
  expect_end(r, "Elements");
}

// MSH 4.1's $Elements: blocks "entityDim entityTag elementType numElementsInBlock", each of
// lines "elementTag nodeTag...".
void read_elements_41(MshReader& r, Contents& c) {
  Records s{"Elements", "elements", 0};
  const auto head = header<4>(r, s.section);
  const Count blocks = checked_count(r, head[0], {"Elements", "entity blocks"}, kHeaderBytes);
  s.declared = checked_count(r, head[1], s, kElementBytes);
  Count done = 0;
  std::string line;
  for (Count b = 0; b < blocks; ++b) {
    next_record(r, s, done, line);
    const auto block = integers<4>(r, line, "an element block's header (dim tag type count)");
    nodes_of_type(r, block[2], line);
    if (block[3] < 0 || static_cast<Count>(block[3]) > s.declared - done)
      r.fail(r.at() + ": an element block of " + std::to_string(block[3]) +
             " elements where the header's " + std::to_string(s.declared) + " leave " +
             std::to_string(s.declared - done));
    const Count end = done + static_cast<Count>(block[3]);
    for (; done < end; ++done) {
      next_record(r, s, done, line);
      const auto words = words_of(line);
      check_element_words(r, line, block[2], words.size(), 1);
      const auto order = static_cast<std::int64_t>(c.tets.size());  // as listed
      add_element(r, line, words, {block[2], block[1], order, 1}, c);
    }
  }
  expect_end(r, "Elements");
}

// An element tag names one element: gmsh's MSH 2.2 reader keeps the last element of a tag and
// drops the other without a word (a body with a hole), also when a boundary triangle listed
// after the tetrahedra reuses a tetrahedron's tag.
void refuse_repeated_element_tags(const MshReader& r,
                                  std::vector<std::pair<std::int64_t, Count>>& tags) {
  std::sort(tags.begin(), tags.end());
  const auto twice = std::adjacent_find(
      tags.begin(), tags.end(), [](const auto& a, const auto& b) { return a.first == b.first; });
  if (twice != tags.end())
    r.fail("element tag " + std::to_string(twice->first) + " is used twice (lines " +
           std::to_string(twice->second) + " and " + std::to_string(std::next(twice)->second) +
           "): a tag names one element (gmsh would keep the last and drop the other; number "
           "the elements of every type from one sequence)");
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

// The version from $MeshFormat ("version file-type data-size"): 2 (2.x) or 4 (4.1), ASCII only.
int read_format(MshReader& r) {
  std::string line;
  if (!r.next(line) || line != "$MeshFormat")
    r.fail(line.rfind("\xEF\xBB\xBF", 0) == 0
               ? "it starts with a byte-order mark before $MeshFormat: save it without one"
               : "not a gmsh .msh file (its first line is not $MeshFormat)");
  if (!r.next(line)) r.fail("the file ends inside section $MeshFormat");
  std::istringstream words(line);
  std::string version;
  int binary = 0;
  if (!(words >> version >> binary))
    r.fail(r.at() + ": '" + line + "' is not 'version file-type data-size'");
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

std::string missing_section(const std::string& section, const std::string& last) {
  if (last.empty()) return "the file has no $" + section + " section";
  return "the file ends after section $" + last + ", with no $" + section + " section";
}

// The sections, each read or skipped to its end line; $Nodes and $Elements once each, in that
// order (the elements refer to the nodes).
void read_sections(MshReader& r, int version, Contents& c) {
  bool nodes = false, elements = false;
  std::string line, last = "MeshFormat";
  while (r.next(line)) {
    if (line.empty() || line[0] != '$') continue;  // gmsh skips lines between sections too
    const std::string section = line.substr(1);
    if (section.rfind("End", 0) == 0) r.fail(r.at() + ": " + line + " without its start");
    if (section == "Nodes") {
      if (nodes) r.fail(r.at() + ": a second $Nodes section");
      version == 4 ? read_nodes_41(r, c.nodes) : read_nodes_22(r, c.nodes);
      sort_nodes(r, c.nodes);
      nodes = true;
    } else if (section == "Elements") {
      // A second one adds its elements to the first's (gmsh reads both): a body
      // stiffer and heavier than the file's first section says.
      if (elements) r.fail(r.at() + ": a second $Elements section");
      if (!nodes)
        r.fail(r.at() +
               ": $Elements before $Nodes: the elements refer to nodes, which a .msh "
               "file defines first (gmsh writes $Nodes, then $Elements)");
      version == 4 ? read_elements_41(r, c) : read_elements_22(r, c);
      refuse_repeated_element_tags(r, c.element_tags);
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
}

}  // namespace

MshFile read_msh_file(const std::string& path) {
  MshReader r(path, checked_file_size(path));
  const int version = read_format(r);
  Contents c;
  read_sections(r, version, c);
  // gmsh's getElementsByType lists the volumes by tag, each volume's tetrahedra in its order.
  std::sort(c.tets.begin(), c.tets.end(), [](const Tet& a, const Tet& b) {
    return a.entity != b.entity ? a.entity < b.entity : a.order < b.order;
  });
  MshFile file;
  file.node_tags.reserve(c.nodes.size());
  file.xyz.reserve(3 * c.nodes.size());
  for (const Node& node : c.nodes) {
    file.node_tags.push_back(node.tag);
    file.xyz.insert(file.xyz.end(), node.x.begin(), node.x.end());
  }
  for (const Tet& tet : c.tets) {
    file.tet_tags.push_back(tet.tag);
    file.tets.push_back(tet.nodes);
  }
  file.other_volume = std::move(c.other_volume);
  return file;
}

}  // namespace fem
