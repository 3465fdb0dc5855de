#ifndef CLOTHWIND_SIM_JSON_COMMENTS_H_
#define CLOTHWIND_SIM_JSON_COMMENTS_H_

#include <string>

#include <nlohmann/json.hpp>

namespace clothwind::sim {

// Removes `// ...` line comments and `/* ... */` block comments that lie outside JSON strings,
// so that files ArcSim accepts (its JSON reader tolerates comments) parse with a strict parser.
// Comments are replaced by spaces (newlines kept), so line and column numbers that the parser
// reports still point into the original file.
//
// Inputs:
//   text  JSON text, possibly with comments
// Returns the same text with comments blanked out.
// Throws std::runtime_error if a block comment is not closed (naming the line where it opened).
std::string StripJsonComments(const std::string& text);

// Deepest nesting of arrays and objects ParseJsonWithComments accepts.
constexpr int kMaxJsonDepth = 256;

// Parses a hand-written JSON file's text (comments allowed, as StripJsonComments) and refuses a
// key given twice in one object: a strict parser keeps the last silently, so a file that says
// "frame_steps": 8 and later "frame_steps": 1000 would run with the second, unseen by its author.
// Also refuses arrays and objects nested more than kMaxJsonDepth deep: copying or printing the
// parsed value recurses once per level, and a hostile file nested millions deep overflowed the
// stack.
//
// Inputs:
//   text  JSON text, possibly with comments
// Returns the parsed value.
// Throws nlohmann::json::parse_error on invalid JSON (its byte offset points into `text`), and
// std::runtime_error naming the repeated key and the object holding it (e.g. `cloths[0]`), or the
// line ("line 3: ...") where the nesting passes kMaxJsonDepth.
nlohmann::json ParseJsonWithComments(const std::string& text);

}  // namespace clothwind::sim

#endif  // CLOTHWIND_SIM_JSON_COMMENTS_H_
