#ifndef CLOTHWIND_COMMON_FRAME_PATTERN_H_
#define CLOTHWIND_COMMON_FRAME_PATTERN_H_

#include <cctype>
#include <string>

namespace clothwind {

// Whether `p` is a frame file pattern as label.json's "frame_pattern" (docs/dataset.md): a printf
// pattern with exactly one integer conversion and nothing else printf would read ("%03d.jpg"),
// and no folder. Readers of datasets (learn's reader, data's index and contact sheets) check it
// before handing it to snprintf: "%s.jpg" there reads a string from nowhere and crashes.
// Inputs: p, the pattern. Returns true when it is one.
inline bool ValidFramePattern(const std::string& p) {
  const size_t pos = p.find('%');
  if (pos == std::string::npos || p.find('%', pos + 1) != std::string::npos) return false;
  size_t i = pos + 1;
  while (i < p.size() && std::isdigit(static_cast<unsigned char>(p[i]))) ++i;
  return i < p.size() && p[i] == 'd' && p.find('/') == std::string::npos;
}

}  // namespace clothwind

#endif  // CLOTHWIND_COMMON_FRAME_PATTERN_H_
