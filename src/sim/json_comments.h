#ifndef CLOTHWIND_SIM_JSON_COMMENTS_H_
#define CLOTHWIND_SIM_JSON_COMMENTS_H_

#include <string>

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

}  // namespace clothwind::sim

#endif  // CLOTHWIND_SIM_JSON_COMMENTS_H_
