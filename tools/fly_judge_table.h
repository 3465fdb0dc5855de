// The accuracy table `clothwind train-fly-judge` prints: a header and a row per split, built from
// the same column widths and the accuracy's own wind-speed bands, so each band's label stands over
// its values. (The header was a fixed string whose band labels drifted off their columns, and the
// split column was padded by bytes: "test±1" holds a two-byte "±".)
// Templates over the accuracy type (learn::FlyJudgeAccuracy: count, right, accuracy(), bands of
// low, high, count, right) so the tools' tests reach them without the learn library.
#ifndef CLOTHWIND_TOOLS_FLY_JUDGE_TABLE_H_
#define CLOTHWIND_TOOLS_FLY_JUDGE_TABLE_H_

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

namespace clothwind::tools {

// Columns a UTF-8 text takes on a terminal: its code points (no wide characters in the table).
inline size_t DisplayWidth(const std::string& text) {
  return static_cast<size_t>(
      std::count_if(text.begin(), text.end(), [](char c) { return (static_cast<unsigned char>(c) & 0xC0) != 0x80; }));
}

// `text` padded with spaces to `width` columns, on the right (left-aligned) or on the left.
inline std::string PadTo(const std::string& text, size_t width, bool left_aligned) {
  const size_t w = DisplayWidth(text);
  if (w >= width) return text;
  return left_aligned ? text + std::string(width - w, ' ') : std::string(width - w, ' ') + text;
}

// Widths of the fixed columns: split (up to "test±10"), windows, right, accuracy ("99.98 %").
constexpr size_t kSplitColumn = 7, kWindowsColumn = 7, kRightColumn = 7, kAccuracyColumn = 11;
constexpr size_t kMinBandColumn = 8;  // "  100.00"

// A band's label: "0-2 m/s"; the last band is open above: "8- m/s".
template <typename Band>
std::string FlyJudgeBandLabel(const Band& band, bool last) {
  char label[64];
  if (last) std::snprintf(label, sizeof label, "%g- m/s", band.low);
  else std::snprintf(label, sizeof label, "%g-%g m/s", band.low, band.high);
  return label;
}

// The width of every band column: the widest label, at least kMinBandColumn.
template <typename Band>
size_t FlyJudgeBandColumn(const std::vector<Band>& bands) {
  size_t width = kMinBandColumn;
  for (size_t i = 0; i < bands.size(); ++i)
    width = std::max(width, DisplayWidth(FlyJudgeBandLabel(bands[i], i + 1 == bands.size())));
  return width;
}

// The header line over rows of accuracies with these bands.
template <typename Band>
std::string FlyJudgeHeader(const std::vector<Band>& bands) {
  std::string line = PadTo("split", kSplitColumn, true) + " " + PadTo("windows", kWindowsColumn, false) + " " +
                     PadTo("right", kRightColumn, false) + " " + PadTo("accuracy", kAccuracyColumn, false);
  const size_t band_column = FlyJudgeBandColumn(bands);
  for (size_t i = 0; i < bands.size(); ++i)
    line += " " + PadTo(FlyJudgeBandLabel(bands[i], i + 1 == bands.size()), band_column, false);
  return line + "\n";
}

// One line of the table: split, windows, right, accuracy and the accuracy per band [%].
template <typename Accuracy>
std::string FlyJudgeRow(const std::string& split, const Accuracy& a) {
  char field[64];
  std::string row = PadTo(split, kSplitColumn, true);
  std::snprintf(field, sizeof field, " %*d %*d %*.2f %%", static_cast<int>(kWindowsColumn), a.count,
                static_cast<int>(kRightColumn), a.right, static_cast<int>(kAccuracyColumn - 2), 100 * a.accuracy());
  row += field;
  const int band_column = static_cast<int>(FlyJudgeBandColumn(a.bands));
  for (const auto& b : a.bands) {
    // An empty band has no accuracy: "-" (as eval's JSON has null), not 0 %, which reads as a failure.
    if (b.count > 0) std::snprintf(field, sizeof field, " %*.2f", band_column, 100.0 * b.right / b.count);
    else std::snprintf(field, sizeof field, " %*s", band_column, "-");
    row += field;
  }
  return row + "\n";
}

}  // namespace clothwind::tools

#endif  // CLOTHWIND_TOOLS_FLY_JUDGE_TABLE_H_
