// A .msh file's structure checked in plain C++ before gmsh reads it: gmsh sizes its arrays by
// the counts in a file's headers and keeps the last of two nodes with one tag, so a cut or
// corrupt file could take the machine's memory (a 327-byte file claiming 1e9 nodes took 20 GiB)
// or silently change the body. Every program and the library read meshes through load_mesh,
// which calls this first.
#pragma once

#include <string>

namespace fem {

// Throws MeshError, naming the file and the cause, for: an empty path, a directory or other
// non-regular file, an empty file, a file that is not an ASCII MSH 2.2 or 4.1 file (a
// byte-order mark named), a header count ($Nodes, $Elements and their blocks, $Entities,
// $PhysicalNames, the data sections' tags) that the bytes left cannot hold, checked before
// anything is sized by it; a file that ends inside or after a section ("the file ends inside
// section $Nodes"), a missing $Nodes or $Elements or a second one; a node line without its
// coordinates, an element line without its type's nodes; a node tag below 1 or defined twice.
// Reads the file once; its memory is one tag per node, bounded by the file's size.
void check_msh_file(const std::string& path);

}  // namespace fem
