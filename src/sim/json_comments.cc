#include "sim/json_comments.h"

#include <stdexcept>

namespace clothwind::sim {

std::string StripJsonComments(const std::string& text) {
  std::string out = text;
  const size_t n = text.size();
  bool in_string = false;
  int line = 1;
  for (size_t i = 0; i < n; ++i) {
    const char c = text[i];
    if (c == '\n') ++line;
    if (in_string) {
      if (c == '\\') {
        ++i;  // Skip the escaped character (it may be a quote).
        if (i < n && text[i] == '\n') ++line;
      } else if (c == '"') {
        in_string = false;
      }
      continue;
    }
    if (c == '"') {
      in_string = true;
    } else if (c == '/' && i + 1 < n && text[i + 1] == '/') {
      while (i < n && text[i] != '\n') out[i++] = ' ';
      if (i < n) ++line;  // The newline itself is kept.
    } else if (c == '/' && i + 1 < n && text[i + 1] == '*') {
      const int open_line = line;
      out[i] = out[i + 1] = ' ';
      i += 2;
      while (i < n && !(text[i] == '*' && i + 1 < n && text[i + 1] == '/')) {
        if (text[i] == '\n') {
          ++line;
        } else {
          out[i] = ' ';
        }
        ++i;
      }
      if (i >= n) {
        throw std::runtime_error("unterminated /* comment opened on line " +
                                 std::to_string(open_line));
      }
      out[i] = out[i + 1] = ' ';
      ++i;
    }
  }
  return out;
}

}  // namespace clothwind::sim
