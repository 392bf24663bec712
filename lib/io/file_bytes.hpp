// Whole-file reads: every reader parses from memory, which is both the fastest way to read
// a point cloud and what lets the fuzzers skip the file system.
#pragma once

#include <string>

namespace gmpu::io::detail {

// The file's bytes. GMPU_ERROR_IO (naming the path and the system's reason) when it is
// missing, unreadable or a directory.
std::string read_file_bytes(const std::string &path);

}  // namespace gmpu::io::detail
