// Mesh loading by the course's own reader (common/msh_read.hpp, no gmsh SDK): the committed
// test mesh, gmsh's order of the tetrahedra, and every bad input with its clear error message.
#include <Eigen/LU>
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <sstream>

#include "catch2_compat.hpp"
#include "common/mesh.hpp"
#include "common/msh_read.hpp"
#include "support.hpp"

using namespace fem;
using fem::test::contains_text;

namespace {

// Writes a small MSH 2.2 file: nodes "x y z" and elements (gmsh type, node list).
std::string write_msh(const std::string& name, const std::vector<std::string>& nodes,
                      const std::vector<std::pair<int, std::string>>& elements) {
  const auto path = std::filesystem::temp_directory_path() / ("fem_test_" + name + ".msh");
  std::ofstream out(path);
  out << "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n" << nodes.size() << "\n";
  for (std::size_t i = 0; i < nodes.size(); ++i) out << i + 1 << " " << nodes[i] << "\n";
  out << "$EndNodes\n$Elements\n" << elements.size() << "\n";
  for (std::size_t e = 0; e < elements.size(); ++e)
    out << e + 1 << " " << elements[e].first << " 2 0 1 " << elements[e].second << "\n";
  out << "$EndElements\n";
  return path.string();
}

const std::vector<std::string> kUnitTet = {"0 0 0", "1 0 0", "0 1 0", "0 0 1"};

}  // namespace

TEST_CASE("the committed test mesh loads with its boundary", "[mesh]") {
  const TetMesh mesh = test::test_mesh();
  CHECK(mesh.num_nodes() > 0);
  CHECK(mesh.num_nodes() <= 300);
  CHECK(mesh.num_tets() > 0);
  CHECK(mesh.dropped_nodes == 0);
  // A closed surface: every boundary edge is shared by exactly two boundary triangles,
  // and by Euler's formula for a sphere-like surface V - E + F = 2.
  std::map<std::pair<int, int>, int> edges;
  for (const auto& t : mesh.boundary)
    for (int k = 0; k < 3; ++k) {
      const int a = t[k], b = t[(k + 1) % 3];
      ++edges[{std::min(a, b), std::max(a, b)}];
    }
  for (const auto& [edge, count] : edges) CHECK(count == 2);
  std::set<int> surface_nodes;
  for (const auto& t : mesh.boundary) surface_nodes.insert({t[0], t[1], t[2]});
  CHECK(static_cast<long>(surface_nodes.size()) - static_cast<long>(edges.size()) +
            static_cast<long>(mesh.boundary.size()) ==
        2);
}

TEST_CASE("a missing file is reported with its name", "[mesh]") {
  CHECK_THROWS_WITH(load_mesh("/nonexistent/nothing.msh"),
                    contains_text("/nonexistent/nothing.msh") && contains_text("cannot open"));
}

TEST_CASE("a file that is not a mesh is reported", "[mesh]") {
  const auto path = std::filesystem::temp_directory_path() / "fem_test_not_a_mesh.msh";
  std::ofstream(path) << "this is not a mesh\n";
  CHECK_THROWS_AS(load_mesh(path.string()), MeshError);
  CHECK_THROWS_WITH(load_mesh(path.string()), contains_text(path.string()));
}

TEST_CASE("a mesh without tetrahedra is reported", "[mesh]") {
  const auto path = write_msh("no_tets", {"0 0 0", "1 0 0", "0 1 0"}, {{2, "1 2 3"}});
  CHECK_THROWS_WITH(load_mesh(path), contains_text("no tetrahedra"));
}

TEST_CASE("10-node tetrahedra are refused as what they are, with what to do", "[mesh]") {
  const auto path = write_msh("tet10",
                              {"0 0 0", "1 0 0", "0 1 0", "0 0 1", "0.5 0 0", "0.5 0.5 0",
                               "0 0.5 0", "0 0 0.5", "0 0.5 0.5", "0.5 0 0.5"},
                              {{11, "1 2 3 4 5 6 7 8 9 10"}});
  CHECK_THROWS_AS(load_mesh(path), MeshError);
  CHECK_THROWS_WITH(load_mesh(path), contains_text("1 Tetrahedron 10 (gmsh type 11, 10 nodes)") &&
                                         contains_text("setOrder(1)"));
}

TEST_CASE("tetrahedra beside hexahedra are refused, not loaded without the hexahedra", "[mesh]") {
  const auto path = write_msh(
      "tet_hex", {"0 0 0", "1 0 0", "1 1 0", "0 1 0", "0 0 1", "1 0 1", "1 1 1", "0 1 1", "0 0 2"},
      {{5, "1 2 3 4 5 6 7 8"}, {5, "1 2 3 4 5 6 7 8"}, {4, "5 6 8 9"}});
  CHECK_THROWS_WITH(load_mesh(path), contains_text("2 Hexahedron 8 (gmsh type 5, 8 nodes)") &&
                                         contains_text("tetrahedra only"));
  // The tetrahedron alone loads.
  CHECK(load_mesh(write_msh("tet_alone", {"0 0 1", "1 0 1", "0 1 1", "0 0 2"}, {{4, "1 2 3 4"}}))
            .num_tets() == 1);
}

TEST_CASE("a degenerate tetrahedron is reported", "[mesh]") {
  const auto path = write_msh("flat", {"0 0 0", "1 0 0", "0 1 0", "1 1 0"}, {{4, "1 2 3 4"}});
  CHECK_THROWS_WITH(load_mesh(path), contains_text("degenerate"));
}

TEST_CASE("an error names nodes and tetrahedra by the file's tags, not by position", "[mesh]") {
  // Element tags 1 (a triangle), 2 (a good tetrahedron), 3 (a flat one: the second
  // tetrahedron, index 1); node tags from 1, so the third node is node 3 (index 2).
  const auto flat = write_msh("flat_tagged", {"0 0 0", "1 0 0", "0 1 0", "0 0 1", "1 1 0"},
                              {{2, "1 2 3"}, {4, "1 2 3 4"}, {4, "1 2 3 5"}});
  CHECK_THROWS_WITH(load_mesh(flat), contains_text("tetrahedron 3 (element tag in the file)"));
  auto nodes = kUnitTet;
  nodes[2] = "0 nan 0";
  CHECK_THROWS_WITH(load_mesh(write_msh("nan_tagged", nodes, {{4, "1 2 3 4"}})),
                    contains_text("node 3 (tag in the file)"));
}

TEST_CASE("NaN or infinite coordinates are reported", "[mesh]") {
  auto nodes = kUnitTet;
  nodes[2] = "0 nan 0";
  CHECK_THROWS_WITH(load_mesh(write_msh("nan", nodes, {{4, "1 2 3 4"}})), contains_text("NaN"));
  nodes[2] = "0 inf 0";
  CHECK_THROWS_WITH(load_mesh(write_msh("inf", nodes, {{4, "1 2 3 4"}})),
                    contains_text("infinite"));
}

TEST_CASE("an inverted tetrahedron is reoriented and counted", "[mesh]") {
  const TetMesh mesh = load_mesh(write_msh("inverted", kUnitTet, {{4, "1 3 2 4"}}));
  REQUIRE(mesh.num_tets() == 1);
  CHECK(mesh.reoriented_tets == 1);
  Eigen::Matrix3d Dm;
  for (int i = 0; i < 3; ++i)
    Dm.col(i) = mesh.X.col(mesh.tets[0][i + 1]) - mesh.X.col(mesh.tets[0][0]);
  CHECK(Dm.determinant() > 0.0);
  CHECK(mesh.boundary.size() == 4);
}

TEST_CASE("nodes used by no tetrahedron are dropped", "[mesh]") {
  auto nodes = kUnitTet;
  nodes.insert(nodes.begin(), "5 5 5");  // node 1 is unused
  // gmsh itself may already skip a node no element uses: either way it is gone.
  CHECK(load_mesh(write_msh("unused", nodes, {{4, "2 3 4 5"}})).num_nodes() == 4);

  Eigen::Matrix3Xd X(3, 5);
  X << 5, 0, 1, 0, 0,  //
      5, 0, 0, 1, 0,   //
      5, 0, 0, 0, 1;
  const TetMesh mesh = make_mesh(X, {Eigen::Vector4i(1, 2, 3, 4)});
  CHECK(mesh.num_nodes() == 4);
  CHECK(mesh.dropped_nodes == 1);
  CHECK(mesh.X.col(0).norm() == 0.0);  // renumbered: the first used node, (0, 0, 0)
  CHECK(mesh.tets[0] == Eigen::Vector4i(0, 1, 2, 3));
}

// ---- the file's structure, checked as it is read (common/msh_read.hpp) ----------------------
namespace {

std::string write_text(const std::string& name, const std::string& text) {
  const auto path = std::filesystem::temp_directory_path() / ("fem_test_" + name + ".msh");
  std::ofstream(path, std::ios::binary) << text;
  return path.string();
}

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// The committed MSH 4.1 test mesh with `from` replaced by `to` once, after `after`.
std::string edited_beam(const std::string& after, const std::string& from, const std::string& to) {
  std::string text = read_text(test::mesh_path("test_beam.msh"));
  const auto at = text.find(from, text.find(after));
  REQUIRE(at != std::string::npos);
  return text.replace(at, from.size(), to);
}

// The header line that follows `section` ("$Nodes\n") in the test mesh, its second count
// (the nodes or elements) replaced by a billion.
std::string beam_claiming_a_billion(const std::string& section) {
  const std::string text = read_text(test::mesh_path("test_beam.msh"));
  const auto start = text.find(section) + section.size();
  std::istringstream header(text.substr(start, text.find('\n', start) - start));
  std::string blocks, count;
  header >> blocks >> count;
  return edited_beam(section, section + blocks + " " + count + " ",
                     section + blocks + " 1000000000 ");
}

std::string cube22(const std::string& node_count = "8", const std::string& node8 = "8 1 1 1") {
  return "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n" + node_count +
         "\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 1 1 0\n5 0 0 1\n6 1 0 1\n7 0 1 1\n" + node8 +
         "\n$EndNodes\n$Elements\n6\n1 4 2 0 1 1 2 4 8\n2 4 2 0 1 1 2 8 6\n3 4 2 0 1 1 3 8 4\n"
         "4 4 2 0 1 1 3 7 8\n5 4 2 0 1 1 5 6 8\n6 4 2 0 1 1 5 8 7\n$EndElements\n";
}

}  // namespace

TEST_CASE("the committed meshes pass the structure check, also with CRLF line ends", "[mesh]") {
  CHECK(load_mesh(write_text("cube22", cube22())).num_tets() == 6);
  std::string crlf = read_text(test::mesh_path("test_beam.msh"));
  for (auto at = crlf.find('\n'); at != std::string::npos; at = crlf.find('\n', at + 2))
    crlf.insert(at, "\r");
  CHECK(load_mesh(write_text("crlf", crlf)).num_tets() == test::test_mesh().num_tets());
}

TEST_CASE("a node tag defined twice is refused, not the last definition kept", "[mesh]") {
  // MSH 2.2: a ninth line defines tag 7 again, at (0,1,2); gmsh alone keeps it, moves node 7.
  CHECK_THROWS_WITH(load_mesh(write_text("dup22", cube22("9", "8 1 1 1\n7 0 1 2"))),
                    contains_text("duplicate node tag 7 (lines 12 and 14)"));
  // MSH 4.1: the second node's tag line repeats the first's.
  CHECK_THROWS_WITH(load_mesh(write_text("dup41", edited_beam("$Nodes", "\n2\n", "\n1\n"))),
                    contains_text("duplicate node tag 1"));
}

TEST_CASE("a header count the file's size cannot hold is refused with both numbers", "[mesh]") {
  const auto nodes22 = write_text("huge22", cube22("1000000000"));
  CHECK_THROWS_WITH(load_mesh(nodes22),
                    contains_text("declares 1000000000 nodes, more than the file can hold") &&
                        contains_text("room for at most"));
  CHECK_THROWS_WITH(load_mesh(write_text("huge41", beam_claiming_a_billion("$Nodes\n"))),
                    contains_text("$Nodes section declares 1000000000 nodes"));
  CHECK_THROWS_WITH(load_mesh(write_text("hugeel41", beam_claiming_a_billion("$Elements\n"))),
                    contains_text("$Elements section declares 1000000000 elements"));
  std::string elements22 = cube22();
  elements22.replace(elements22.find("\n6\n"), 3, "\n1000000000\n");
  CHECK_THROWS_WITH(load_mesh(write_text("hugeel22", elements22)),
                    contains_text("$Elements section declares 1000000000 elements"));
  std::string word22 = cube22();
  word22.replace(word22.find("\n6\n"), 3, "\n1e9\n");
  CHECK_THROWS_WITH(load_mesh(write_text("word22", word22)),
                    contains_text("'1e9' is not the section's header"));
}

TEST_CASE("a cut file is refused naming the section it ends inside or after", "[mesh]") {
  const std::string cube = cube22();
  CHECK_THROWS_WITH(load_mesh(write_text("cut22_nodes", cube.substr(0, cube.find("7 0 1 1")))),
                    contains_text("the file ends inside section $Nodes"));
  CHECK_THROWS_WITH(load_mesh(write_text("cut22_after", cube.substr(0, cube.find("$Elements")))),
                    contains_text("the file ends after section $Nodes, with no $Elements"));
  CHECK_THROWS_WITH(load_mesh(write_text("cut22_elements", cube.substr(0, cube.size() - 14))),
                    contains_text("the file ends inside section $Elements"));
  const std::string beam = read_text(test::mesh_path("test_beam.msh"));
  const auto end_nodes = beam.find("$EndNodes\n") + 10;
  CHECK_THROWS_WITH(load_mesh(write_text("cut41_after", beam.substr(0, end_nodes))),
                    contains_text("the file ends after section $Nodes, with no $Elements"));
  CHECK_THROWS_WITH(load_mesh(write_text("cut41_nodes", beam.substr(0, end_nodes - 200))),
                    contains_text("the file ends inside section $Nodes (after "));
}

TEST_CASE("a node without its coordinates, a second $Elements section are refused", "[mesh]") {
  std::string no_z = cube22();
  no_z.replace(no_z.find("\n3 0 1 0\n"), 9, "\n3 0 1\n");
  CHECK_THROWS_WITH(load_mesh(write_text("no_z", no_z)),
                    contains_text("line 8: '3 0 1' is not a node (tag x y z)"));
  CHECK_THROWS_WITH(
      load_mesh(write_text("no_z41", edited_beam("$Nodes", "\n0 0 0.1\n", "\n0 0\n"))),
      contains_text("'0 0' is not a node's x y z"));
  const std::string cube = cube22();
  const std::string twice = cube + cube.substr(cube.find("$Elements"));
  CHECK_THROWS_WITH(load_mesh(write_text("elements_twice", twice)),
                    contains_text("a second $Elements section"));
}

TEST_CASE("two tetrahedra on the same four nodes are refused, by the file's tags", "[mesh]") {
  CHECK_THROWS_WITH(load_mesh(write_msh("tet_twice", kUnitTet, {{4, "1 2 3 4"}, {4, "2 1 4 3"}})),
                    contains_text("tetrahedron 1 (element tag in the file) and tetrahedron 2 "
                                  "(element tag in the file) have the same four nodes"));
}

TEST_CASE("the counts of $PhysicalNames and of data sections are held against the file too",
          "[mesh]") {
  const std::string cube = cube22();
  const std::string head = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n";
  CHECK_THROWS_WITH(
      load_mesh(write_text("names_huge", head +
                                             "$PhysicalNames\n1000000000\n3 1 \"body\"\n"
                                             "$EndPhysicalNames\n" +
                                             cube.substr(head.size()))),
      contains_text("$PhysicalNames section declares 1000000000 names"));
  const std::string data = "$NodeData\n1\n\"d\"\n1\n0.0\n3\n0\n1\n";
  std::string entries;
  for (int i = 1; i <= 8; ++i) entries += std::to_string(i) + " 0.5\n";
  CHECK(load_mesh(write_text("data_ok", cube + data + "8\n" + entries + "$EndNodeData\n"))
            .num_tets() == 6);
  CHECK_THROWS_WITH(
      load_mesh(write_text("data_huge", cube + data + "1000000000\n1 0.5\n$EndNodeData\n")),
      contains_text("$NodeData section declares 1000000000 entries"));
}

TEST_CASE("an element line short of a node, a node tag 0, a byte-order mark are named", "[mesh]") {
  // gmsh read the tetrahedron one node short together with the next line, as a prism.
  CHECK_THROWS_WITH(
      load_mesh(write_msh("tet_short", kUnitTet, {{4, "1 2 3"}, {4, "1 2 3 4"}})),
      contains_text("element '1 4 2 0 1 1 2 3' of gmsh type 4 lists 3 nodes, not its 4"));
  CHECK_THROWS_WITH(
      load_mesh(write_text(
          "tet_short41", edited_beam("$Elements", "\n1 106 162 151 138 \n", "\n1 106 162 151\n"))),
      contains_text("'1 106 162 151' of gmsh type 4 lists 3 nodes, not its 4"));
  std::string tag0 = cube22();
  tag0.replace(tag0.find("\n1 0 0 0\n"), 9, "\n0 0 0 0\n");
  CHECK_THROWS_WITH(load_mesh(write_text("tag0", tag0)),
                    contains_text("node tag 0 (gmsh numbers nodes from 1)"));
  CHECK_THROWS_WITH(load_mesh(write_text("bom", "\xEF\xBB\xBF" + cube22())),
                    contains_text("byte-order mark"));
}

TEST_CASE("a path that names no mesh file is refused as what it is", "[mesh]") {
  CHECK_THROWS_WITH(load_mesh(""), contains_text("an empty path names no file"));
  CHECK_THROWS_WITH(load_mesh(std::filesystem::temp_directory_path().string()),
                    contains_text("is a directory"));
  CHECK_THROWS_WITH(load_mesh("/dev/null"), contains_text("is not a regular file"));
  CHECK_THROWS_WITH(load_mesh(write_text("empty", "")), contains_text("the file is empty"));
  CHECK_THROWS_WITH(load_mesh(write_text("geo", "Point(1) = {0, 0, 0};\n")),
                    contains_text("not a gmsh .msh file"));
  CHECK_THROWS_WITH(load_mesh(write_text("binary", edited_beam("", "4.1 0 8", "4.1 1 8"))),
                    contains_text("a binary .msh file"));
  CHECK_THROWS_WITH(load_mesh(write_text("v40", edited_beam("", "4.1 0 8", "4 0 8"))),
                    contains_text("MSH version 4: the programs read MSH 4.1 and 2.2"));
}

// ---- element tags, and the minor cases of the fifth review (A2) -----------------------------

TEST_CASE("a repeated element tag is refused with both lines, across blocks and types", "[mesh]") {
  // MSH 2.2: tetrahedra tagged 1, 2, 3, 3, 5, 6 (lines 17 to 22): gmsh kept the second 3 only.
  std::string twice = cube22();
  twice.replace(twice.find("\n4 4 2"), 6, "\n3 4 2");
  CHECK_THROWS_WITH(load_mesh(write_text("etag22", twice)),
                    contains_text("element tag 3 is used twice (lines 19 and 20)"));
  // A boundary triangle after the tetrahedra reuses tetrahedron 3's tag (line 23).
  std::string triangle = cube22();
  triangle.replace(triangle.find("\n6\n"), 3, "\n7\n");
  triangle.replace(triangle.find("$EndElements"), 0, "3 2 2 0 2 1 2 4\n");
  CHECK_THROWS_WITH(load_mesh(write_text("etag22_tri", triangle)),
                    contains_text("element tag 3 is used twice (lines 19 and 23)"));
  // MSH 4.1: a triangle block before the tetrahedra's, its triangle tagged 7 as a tetrahedron.
  const std::string blocks = edited_beam("$Elements", "$Elements\n1 434 1 434\n3 1 4 434\n",
                                         "$Elements\n2 435 1 434\n2 1 2 1\n7 1 2 3\n3 1 4 434\n");
  CHECK_THROWS_WITH(load_mesh(write_text("etag41", blocks)),
                    contains_text("element tag 7 is used twice (lines 451 and 459)"));
}

TEST_CASE("tetrahedra come in gmsh's order: by volume, then by tag (2.2) or as listed (4.1)",
          "[mesh]") {
  // MSH 2.2 "tag type 2 physical elementary nodes": volume 2 first in the file, tags unordered.
  const std::string head = cube22().substr(0, cube22().find("$Elements"));
  const MshFile file22 = read_msh_file(
      write_text("order22", head + "$Elements\n4\n9 4 2 0 2 1 2 4 8\n5 4 2 0 1 1 2 8 6\n"
                                   "2 4 2 0 1 1 3 8 4\n7 4 2 0 2 1 3 7 8\n$EndElements\n"));
  CHECK(file22.tet_tags == std::vector<std::int64_t>{2, 5, 7, 9});
  // MSH 4.1: volume 2's block first, its tetrahedra tagged 9 then 3.
  const MshFile file41 = read_msh_file(write_text(
      "order41", edited_beam("$Elements", "$Elements\n1 434 1 434\n3 1 4 434\n",
                             "$Elements\n2 436 1 1000\n3 2 4 2\n999 1 2 3 4\n998 1 2 3 5\n"
                             "3 1 4 434\n")));
  REQUIRE(file41.tet_tags.size() == 436);
  CHECK(file41.tet_tags[0] == 1);
  CHECK(file41.tet_tags[434] == 999);
  CHECK(file41.tet_tags[435] == 998);
}

TEST_CASE("coordinates beyond 1e100 are refused by the node, before a volume overflows", "[mesh]") {
  CHECK_THROWS_WITH(load_mesh(write_text("far_node", cube22("8", "8 1e300 1 1"))),
                    contains_text("node 8 (tag in the file) lies at (1e+300, 1, 1)") &&
                        contains_text("overflows"));
  auto nodes = kUnitTet;
  nodes[1] = "1e150 0 0";
  CHECK_THROWS_WITH(load_mesh(write_msh("far150", nodes, {{4, "1 2 3 4"}})),
                    contains_text("node 2 (tag in the file) lies at (1e+150, 0, 0)"));
  // Large but within: the unit tetrahedron scaled by 1e99, a volume of 1.7e296.
  CHECK(
      load_mesh(write_msh("far99", {"0 0 0", "1e99 0 0", "0 1e99 0", "0 0 1e99"}, {{4, "1 2 3 4"}}))
          .num_tets() == 1);
}

TEST_CASE("an element type gmsh does not define, or of another node count, names line and type",
          "[mesh]") {
  CHECK_THROWS_WITH(load_mesh(write_msh("type200", kUnitTet, {{200, "1 2 3 4"}})),
                    contains_text("line 13: '1 200 2 0 1 1 2 3 4' has element type 200, which "
                                  "gmsh does not define"));
  // Type 99 is gmsh's 32-node hexahedron: the line lists 4.
  CHECK_THROWS_WITH(load_mesh(write_msh("type99", kUnitTet, {{99, "1 2 3 4"}})),
                    contains_text("of gmsh type 99 lists 4 nodes, not its 32"));
  CHECK_THROWS_WITH(load_mesh(write_msh("polyhedron", kUnitTet, {{35, "1 2 3 4"}})),
                    contains_text("element type 35 (a polygon, polyhedron or XFEM element"));
  CHECK_THROWS_WITH(
      load_mesh(write_text("type41", edited_beam("$Elements", "\n3 1 4 434\n", "\n3 1 999 434\n"))),
      contains_text("line 450: '3 1 999 434' has element type 999, which gmsh does not define"));
}

TEST_CASE("a coordinate or a node that is not a number is named with its line", "[mesh]") {
  std::string text = cube22();
  text.replace(text.find("\n3 0 1 0\n"), 9, "\n3 0 abc 0\n");
  CHECK_THROWS_WITH(load_mesh(write_text("text22", text)),
                    contains_text("line 8: 'abc' in '3 0 abc 0' is not a number (a node's x y z)"));
  CHECK_THROWS_WITH(
      load_mesh(write_text("text41", edited_beam("$Nodes", "\n0 0 0.1\n", "\n0 0 0.1x\n"))),
      contains_text("'0.1x' in '0 0 0.1x' is not a number"));
  CHECK_THROWS_WITH(load_mesh(write_msh("node_word", kUnitTet, {{4, "1 2 3 four"}})),
                    contains_text("'four' in '1 4 2 0 1 1 2 3 four' is not an integer"));
  CHECK_THROWS_WITH(load_mesh(write_msh("node_99", kUnitTet, {{4, "1 2 3 99"}})),
                    contains_text("line 13: element 1 refers to node 99, which the $Nodes "
                                  "section does not define"));
}

TEST_CASE("elements before nodes, CR line ends and a bad format line are named as such", "[mesh]") {
  const std::string cube = cube22();
  const auto nodes_at = cube.find("$Nodes"), elements_at = cube.find("$Elements");
  const std::string swapped = cube.substr(0, nodes_at) + cube.substr(elements_at) +
                              cube.substr(nodes_at, elements_at - nodes_at);
  CHECK_THROWS_WITH(load_mesh(write_text("elements_first", swapped)),
                    contains_text("line 4: $Elements before $Nodes"));
  std::string cr = cube;
  std::replace(cr.begin(), cr.end(), '\n', '\r');
  CHECK_THROWS_WITH(load_mesh(write_text("cr_only", cr)),
                    contains_text("the file's lines end in CR alone"));
  std::string garbage = cube;
  garbage.replace(garbage.find("2.2 0 8"), 7, "abc");
  CHECK_THROWS_WITH(load_mesh(write_text("format_garbage", garbage)),
                    contains_text("line 2: 'abc' is not 'version file-type data-size'"));
}
