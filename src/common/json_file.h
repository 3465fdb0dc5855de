// Reading JSON files with errors people can act on. nlohmann's own messages read
// "[json.exception.parse_error.101] parse error at line 1, column 1: syntax error while parsing
// value - unexpected end of input; expected '[', '{', or a literal" for an empty file, and a folder
// gave "basic_filebuf::underflow error reading the file: Is a directory": library text, where the
// project's standard is the file, the place and what was expected.
#ifndef CLOTHWIND_COMMON_JSON_FILE_H_
#define CLOTHWIND_COMMON_JSON_FILE_H_

#include <cerrno>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

namespace clothwind {

// An exception's text without nlohmann's tag ("[json.exception.parse_error.101] ") and its
// generic "parse error at " / "syntax error while parsing value - " words: e.g. "line 3, column 9:
// invalid literal; last read: '0.3,n'". Other exceptions' text is returned as it is.
// Inputs: e  what a nlohmann::json call (or anything else) threw.
inline std::string JsonErrorText(const std::exception& e) {
  std::string text = e.what();
  if (text.rfind("[json.exception.", 0) == 0) {
    const size_t end = text.find("] ");
    if (end != std::string::npos) text.erase(0, end + 2);
  }
  for (const char* generic : {"parse error at ", "parse error: "})
    if (text.rfind(generic, 0) == 0) text.erase(0, std::strlen(generic));
  for (const char* generic : {"syntax error while parsing value - ", "syntax error while parsing object - ",
                              "syntax error while parsing array - "}) {
    const size_t at = text.find(generic);
    if (at != std::string::npos) text.erase(at, std::strlen(generic));
  }
  return text;
}

// The text of a file. Throws std::runtime_error "<path>: <why>" for a folder, a file that cannot be
// opened or read, and, unless `allow_empty`, an empty one (or one of whitespace only). A pipe is
// read (`simulate <(...)`, /dev/stdin).
// Inputs: path; what  the file's role, appended to errors in brackets when not empty ("the model's
// architecture").
inline std::string ReadTextFile(const std::string& path, const std::string& what = "", bool allow_empty = false) {
  namespace fs = std::filesystem;
  const std::string role = what.empty() ? "" : " (" + what + ")";
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw std::runtime_error(path + ": a folder, expected a JSON file" + role);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot open: " + std::strerror(errno) + role);
  std::string text;
  try {
    text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  } catch (const std::exception& e) {  // libstdc++'s filebuf throws on a read error (EIO)
    throw std::runtime_error(path + ": cannot read: " + e.what() + role);
  }
  if (in.bad()) throw std::runtime_error(path + ": cannot read" + role);
  if (!allow_empty && text.find_first_not_of(" \t\r\n") == std::string::npos)
    throw std::runtime_error(path + ": the file is empty" + std::string(text.empty() ? "" : " but for whitespace") +
                             ", expected JSON" + role);
  return text;
}

// A JSON file, parsed. Throws std::runtime_error "<path>: ..." as ReadTextFile does, and
// "<path>: not valid JSON: line L, column C: <reason>" (JsonErrorText) when it does not parse.
inline nlohmann::json ReadJsonFile(const std::string& path, const std::string& what = "") {
  const std::string text = ReadTextFile(path, what);
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(path + ": not valid JSON: " + JsonErrorText(e) +
                             (what.empty() ? "" : " (" + what + ")"));
  }
}

}  // namespace clothwind

#endif  // CLOTHWIND_COMMON_JSON_FILE_H_
