// Results written whole or not at all: a file is written under a temporary name in its own
// folder, flushed to the disk, and renamed over the old one (rename(2) replaces a name in one
// step within a file system). A failed write (disk full, quota, I/O error) throws with the
// path and the cause and leaves the earlier file as it was: a full disk never turns a good
// result into a cut one that the next program reads as whole.
#pragma once

#include <functional>
#include <ostream>
#include <stdexcept>
#include <string>

namespace fem {

struct WriteError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Writes the text `write` puts into the stream to `path`, whole or not at all. Throws
// WriteError("cannot write 'PATH': CAUSE").
//
// The failure the tests inject: with FEM_FAIL_WRITES=NAME in the environment, a write of a
// file named NAME (or of every file, for "*") stops half-way with ENOSPC, as on a full disk.
void write_file_atomically(const std::string& path,
                           const std::function<void(std::ostream&)>& write);

// The same for text already made.
void write_file_atomically(const std::string& path, const std::string& text);

// A path that exists and is not a regular file (a device such as /dev/null, a FIFO, a socket,
// a directory; a symbolic link counts as what it points to): the rename would replace the
// node itself (as root, /dev/null), and opening a FIFO blocks until a reader comes. Returns
// "it is CAUSE, not a regular file: ..." for such a path, "" otherwise (no such file, or a
// regular one). Every writer below refuses such a target with it: "cannot write 'PATH': ...".
std::string not_a_regular_file(const std::string& path);

// Before the work: tries what the write will do (makes the temporary name in the folder and
// removes it again), so that a run does not end in "cannot write". Throws WriteError with the
// path and the cause: no such folder, not a regular file, no permission, a read-only file
// system.
void check_writable(const std::string& path);

}  // namespace fem
