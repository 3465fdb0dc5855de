// Telling a path that is there but cannot be read as a file. Why: opening a folder as a stream
// threw "basic_filebuf::underflow ... Is a directory", naming nothing, and a FIFO waited for a
// writer for ever; readers refuse both up front, naming the path. Header-only.
#ifndef CLOTHWIND_COMMON_REGULAR_FILE_H_
#define CLOTHWIND_COMMON_REGULAR_FILE_H_

#include <filesystem>
#include <system_error>

namespace clothwind {

// Input: path. Returns true when something is at `path` and it is not a regular file (a folder,
// a pipe, a device); false for a regular file, and for nothing there (the caller's open says so).
inline bool ExistsButNotARegularFile(const std::filesystem::path& path) {
  std::error_code ec;
  return std::filesystem::exists(path, ec) && !std::filesystem::is_regular_file(path, ec);
}

}  // namespace clothwind

#endif  // CLOTHWIND_COMMON_REGULAR_FILE_H_
