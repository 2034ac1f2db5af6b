// The course's reader of gmsh's ASCII .msh files, MSH 4.1 and 2.2 (common/msh_read.cpp): the
// programs and the library read meshes with it, so that none links the gmsh SDK. It reads what
// gmsh's own reader reads (the same coordinates, parsed by strtod from the same digits; the
// tetrahedra in the order gmsh's API lists them) and refuses, with the line and the cause, what
// gmsh would read wrong or silently change: a header count the file cannot hold (a 327-byte file
// claiming 1e9 nodes once took gmsh 20 GiB), a node or element tag defined twice (gmsh keeps the
// last), a cut file, a line short of its words.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace fem {

// A .msh file's nodes and linear tetrahedra (gmsh type 4), as gmsh's API gives them:
// getNodes sorted by tag, and getElementsByType(4).
struct MshFile {
  std::vector<std::uint64_t> node_tags;  // ascending: node i has the i-th smallest tag
  std::vector<double> xyz;               // node i at 3i, 3i + 1, 3i + 2
  std::vector<std::int64_t> tet_tags;    // the file's element tags, in gmsh's order (below)
  std::vector<std::array<int, 4>> tets;  // node indices into node_tags, as the file lists them
  // Every other volume element type in the file and its count ("Hexahedron 8" -> 40), keyed by
  // gmsh's type number, named as gmsh names it.
  std::map<int, std::pair<std::string, std::size_t>> other_volume;
};

// Reads the file, or throws MeshError naming the file and the cause: an empty path, a directory
// or other non-regular file, an empty file, a file that is not an ASCII MSH 2.2 or 4.1 file (a
// byte-order mark and CR-only line ends named), a header count ($Nodes, $Elements and their
// blocks, $Entities, $PhysicalNames, the data sections' tags) that the bytes left cannot hold,
// checked before anything is sized by it; a file that ends inside or after a section, a missing
// $Nodes or $Elements or a second one, $Elements before $Nodes; a node line without its
// coordinates or with a word that is not a number, an element line without its type's nodes, an
// element type gmsh does not define, a node tag below 1, a node or an element tag used twice
// (both lines named), an element on a node that $Nodes does not define.
// Tetrahedra come in gmsh's order: by volume (entity tag) ascending, then in MSH 4.1 as listed
// and in MSH 2.2 by element tag. Memory: a node's tag, line and coordinates, an element's tag
// and line, bounded by the file's size.
MshFile read_msh_file(const std::string& path);

}  // namespace fem
