#ifndef CLOTHWIND_COMMON_DATASET_NAMES_H_
#define CLOTHWIND_COMMON_DATASET_NAMES_H_

#include <cctype>
#include <string>

// Names a dataset's files hold (docs/dataset.md) and readers check before using them.
namespace clothwind {

// Whether `name` is a clip folder name as index.json's clips[i].name: one folder inside the
// dataset, not a path out of it ("../x", "/tmp/x") and not hidden (writers' temporaries).
inline bool ValidClipName(const std::string& name) {
  return !name.empty() && name[0] != '.' && name.find('/') == std::string::npos;
}

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

#endif  // CLOTHWIND_COMMON_DATASET_NAMES_H_
