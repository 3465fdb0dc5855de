#include "sim/json_comments.h"

#include <set>
#include <stdexcept>
#include <vector>

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

namespace {

// Throws when arrays and objects nest deeper than kMaxJsonDepth, naming the line where the limit
// is passed. A scan of its own, before the parser: nlohmann parses deep nesting fine, but copying,
// comparing or printing the value recurses once per level (a scene whose "motions" were nested
// 2,000,000 deep crashed the reader with a stack overflow). The parser callback knows the depth
// too, but not the line.
// Inputs: text  JSON with comments already blanked (StripJsonComments), so only strings need
// skipping.
void CheckNesting(const std::string& text) {
  int depth = 0, line = 1;
  bool in_string = false;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '\n') ++line;
    if (in_string) {
      if (c == '\\') {
        ++i;  // the escaped character (it may be a quote)
        if (i < text.size() && text[i] == '\n') ++line;
      } else if (c == '"') {
        in_string = false;
      }
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > kMaxJsonDepth)
        throw std::runtime_error("line " + std::to_string(line) + ": arrays and objects nested more than " +
                                 std::to_string(kMaxJsonDepth) + " deep (no scene or material needs more than a few)");
    } else if (c == ']' || c == '}') {
      --depth;  // (unbalanced brackets are the parser's to name)
    }
  }
}

}  // namespace

nlohmann::json ParseJsonWithComments(const std::string& text) {
  using json = nlohmann::json;
  // One entry per open object or array, outermost first: its keys so far (objects), its element
  // count (arrays) and the key or index it sits at in its parent, to name it in the error.
  struct Open {
    bool object;
    std::set<std::string> keys;
    int elements = 0;
    std::string at;
  };
  std::vector<Open> open;
  std::string last_key;
  auto where = [&] {
    std::string path;
    for (size_t i = 1; i < open.size(); ++i) path += open[i].at;
    return path.empty() ? std::string("the top-level object") : path;
  };
  auto position_in_parent = [&]() -> std::string {
    if (open.empty()) return "";
    if (open.back().object) return (open.size() > 1 ? "." : "") + last_key;
    return "[" + std::to_string(open.back().elements++) + "]";
  };
  const json::parser_callback_t check = [&](int, json::parse_event_t event, json& parsed) {
    switch (event) {
      case json::parse_event_t::object_start:
      case json::parse_event_t::array_start: {
        std::string at = position_in_parent();
        open.push_back({event == json::parse_event_t::object_start, {}, 0, std::move(at)});
        break;
      }
      case json::parse_event_t::object_end:
      case json::parse_event_t::array_end:
        if (!open.empty()) open.pop_back();
        break;
      case json::parse_event_t::key:
        last_key = parsed.get<std::string>();
        if (!open.back().keys.insert(last_key).second)
          throw std::runtime_error("key \"" + last_key + "\" is given twice in " + where() +
                                   " (JSON keeps only the last silently); give it once");
        break;
      case json::parse_event_t::value:
        // A scalar element of an array takes an index; one under a key needs nothing.
        if (!open.empty() && !open.back().object) ++open.back().elements;
        break;
    }
    return true;
  };
  const std::string stripped = StripJsonComments(text);
  CheckNesting(stripped);
  return json::parse(stripped, check);
}

}  // namespace clothwind::sim
