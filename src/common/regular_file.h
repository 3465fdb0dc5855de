// Telling a path that is there but cannot be read as a file. Why: opening a folder as a stream
// threw "basic_filebuf::underflow ... Is a directory", naming nothing, and a FIFO waited for a
// writer for ever; readers refuse both up front, naming the path. Header-only.
#ifndef CLOTHWIND_COMMON_REGULAR_FILE_H_
#define CLOTHWIND_COMMON_REGULAR_FILE_H_

#include <filesystem>
#include <stdexcept>
#include <string>
#include <system_error>

namespace clothwind {

// Input: path. Returns true when something is at `path` and it is not a regular file (a folder,
// a pipe, a device); false for a regular file, and for nothing there (the caller's open says so).
inline bool ExistsButNotARegularFile(const std::filesystem::path& path) {
  std::error_code ec;
  return std::filesystem::exists(path, ec) && !std::filesystem::is_regular_file(path, ec);
}

// Throws std::runtime_error "<path>: a folder, expected <expected>" or "<path>: not a regular file
// (a pipe or a device), expected <expected>" when something at `path` is not a regular file; does
// nothing for a regular file or for nothing there (the caller's open says so). For readers whose
// open would take a folder as an empty file or wait on a pipe for ever.
inline void RefuseNonRegularFile(const std::string& path, const std::string& expected) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw std::runtime_error(path + ": a folder, expected " + expected);
  if (ExistsButNotARegularFile(path))
    throw std::runtime_error(path + ": not a regular file (a pipe or a device), expected " + expected);
}

}  // namespace clothwind

#endif  // CLOTHWIND_COMMON_REGULAR_FILE_H_
