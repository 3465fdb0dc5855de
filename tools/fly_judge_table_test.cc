#include "fly_judge_table.h"

#include <gtest/gtest.h>

namespace clothwind::tools {
namespace {

// The shape of learn::FlyJudgeAccuracy (the table's templates read only these).
struct Accuracy {
  int count = 0, right = 0;
  double accuracy() const { return count > 0 ? static_cast<double>(right) / count : 0.0; }
  struct Band {
    double low = 0, high = 0;
    int count = 0, right = 0;
  };
  std::vector<Band> bands;
};

// The column (of display characters) just past the first `text` in `line`; npos if absent.
size_t EndColumn(const std::string& line, const std::string& text) {
  const size_t at = line.find(text);
  return at == std::string::npos ? std::string::npos : DisplayWidth(line.substr(0, at + text.size()));
}

Accuracy Measured(double band_width) {
  Accuracy a;
  a.count = 4792;
  a.right = 4791;
  const int counts[] = {10, 20, 0, 40, 8}, rights[] = {5, 20, 0, 39, 1};  // 50.00 100.00 - 97.50 12.50
  for (int b = 0; b < 5; ++b) a.bands.push_back({b * band_width, (b + 1) * band_width, counts[b], rights[b]});
  return a;
}

// Each band's label ends in the column its values end in, for a split named with a two-byte "±"
// as for one in ASCII, and for labels wider than the values.
TEST(FlyJudgeTableTest, EachBandLabelStandsOverItsValues) {
  for (double band_width : {2.0, 2.5, 12.5}) {
    const Accuracy a = Measured(band_width);
    const std::string header = FlyJudgeHeader(a.bands);
    const char* values[] = {"50.00", "100.00", "-", "97.50", "12.50"};
    for (const std::string split : {"train", "test±3", "test±12"}) {
      const std::string row = FlyJudgeRow(split, a);
      SCOPED_TRACE("\n" + header + row);
      EXPECT_EQ(EndColumn(header, "windows"), EndColumn(row, "4792"));
      EXPECT_EQ(EndColumn(header, "right"), EndColumn(row, "4791"));
      EXPECT_EQ(EndColumn(header, "accuracy"), EndColumn(row, "99.98 %"));
      // After the fixed columns, so "-" is the band's, not a sign.
      const size_t bands_start = row.find("99.98 %") + 7;
      for (int b = 0; b < 5; ++b) {
        const std::string label = FlyJudgeBandLabel(a.bands[b], b == 4);
        const size_t value_at = row.find(std::string(" ") + values[b], bands_start);
        ASSERT_NE(value_at, std::string::npos) << values[b];
        // The value ends where the label ends.
        const std::string value_end = row.substr(0, value_at + 1 + std::string(values[b]).size());
        EXPECT_EQ(EndColumn(header, label), DisplayWidth(value_end)) << label;
      }
      EXPECT_EQ(DisplayWidth(header), DisplayWidth(row)) << "the row and its header are one width";
    }
  }
  EXPECT_EQ(FlyJudgeBandLabel(Accuracy::Band{0, 2}, false), "0-2 m/s");
  EXPECT_EQ(FlyJudgeBandLabel(Accuracy::Band{8, 10}, true), "8- m/s");
}

TEST(FlyJudgeTableTest, DisplayWidthCountsCodePoints) {
  EXPECT_EQ(DisplayWidth("test±1"), 6u);
  EXPECT_EQ(PadTo("test±1", 7, true), "test±1 ");
  EXPECT_EQ(PadTo("ab", 4, false), "  ab");
  EXPECT_EQ(PadTo("abcdef", 4, true), "abcdef");
}

}  // namespace
}  // namespace clothwind::tools
