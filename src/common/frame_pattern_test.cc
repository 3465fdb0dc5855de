#include "common/frame_pattern.h"

#include <gtest/gtest.h>

namespace clothwind {
namespace {

TEST(FramePatternTest, OneIntegerConversionAndNothingElse) {
  for (const char* good : {"%03d.jpg", "%d.png", "frame_%05d.pgm", "%3d"}) EXPECT_TRUE(ValidFramePattern(good)) << good;
  for (const char* bad : {"%s.jpg", "%d_%d.jpg", "000.jpg", "%.jpg", "sub/%03d.jpg", "%03x.jpg", "%-3d.jpg",
                          "%n.jpg", "%03d%%.jpg", ""})
    EXPECT_FALSE(ValidFramePattern(bad)) << bad;
}

}  // namespace
}  // namespace clothwind
