// The name a mistyped word was most likely meant to be, for "did you mean ...?" (a verb typed
// `make-datset` was told only "A subcommand is required").
#ifndef CLOTHWIND_TOOLS_CLOSEST_NAME_H_
#define CLOTHWIND_TOOLS_CLOSEST_NAME_H_

#include <algorithm>
#include <string>
#include <vector>

namespace clothwind::tools {

// Levenshtein distance: the fewest insertions, deletions and substitutions that turn a into b.
inline size_t EditDistance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

// Inputs: word  what was typed; names  the names it could have meant.
// Returns the name nearest to `word` (the first of equals, in the order given) when it is within
// a third of the word's length (at least 2 edits), else "".
inline std::string ClosestName(const std::string& word, const std::vector<std::string>& names) {
  std::string best;
  size_t best_distance = std::max<size_t>(2, word.size() / 3) + 1;
  for (const std::string& name : names) {
    const size_t d = EditDistance(word, name);
    if (d < best_distance) {
      best = name;
      best_distance = d;
    }
  }
  return best;
}

}  // namespace clothwind::tools

#endif  // CLOTHWIND_TOOLS_CLOSEST_NAME_H_
