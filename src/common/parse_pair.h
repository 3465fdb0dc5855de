#ifndef CLOTHWIND_COMMON_PARSE_PAIR_H_
#define CLOTHWIND_COMMON_PARSE_PAIR_H_

#include <cstddef>
#include <exception>
#include <string>

namespace clothwind {

// "A<sep>B" -> (a, b), each part read whole by `parse` (a callable (const std::string&, size_t*
// chars_read) -> T, as std::stoi or std::stod). Command-line pairs such as a shard "3/8", a range
// "5.1:6.1" or a grid "8x6" share it, so each option only names its separator and its checks.
// Inputs: text; sep, the separator (its first occurrence splits); parse.
// Outputs: a, b. Returns false (a, b then unspecified) unless text is exactly that form.
template <typename T, typename Parse>
bool ParsePair(const std::string& text, char sep, Parse parse, T* a, T* b) {
  const auto at = text.find(sep);
  if (at == std::string::npos) return false;
  try {
    size_t na = 0, nb = 0;
    *a = parse(text.substr(0, at), &na);
    *b = parse(text.substr(at + 1), &nb);
    return na == at && nb == text.size() - at - 1;
  } catch (const std::exception&) {
    return false;
  }
}

}  // namespace clothwind

#endif  // CLOTHWIND_COMMON_PARSE_PAIR_H_
