#include "common/dataset_names.h"

#include <gtest/gtest.h>

namespace clothwind {
namespace {

TEST(FramePatternTest, OneIntegerConversionAndNothingElse) {
  for (const char* good : {"%03d.jpg", "%d.png", "frame_%05d.pgm", "%3d"}) EXPECT_TRUE(ValidFramePattern(good)) << good;
  for (const char* bad : {"%s.jpg", "%d_%d.jpg", "000.jpg", "%.jpg", "sub/%03d.jpg", "%03x.jpg", "%-3d.jpg",
                          "%n.jpg", "%03d%%.jpg", ""})
    EXPECT_FALSE(ValidFramePattern(bad)) << bad;
}

TEST(ClipNameTest, OneVisibleFolderInsideTheDataset) {
  for (const char* good : {"toy-00000", "clip-20231114-221319.999-000000", "a.b"}) EXPECT_TRUE(ValidClipName(good)) << good;
  for (const char* bad : {"", ".hidden", "../x", "/tmp/x", "a/b", ".."}) EXPECT_FALSE(ValidClipName(bad)) << bad;
}

}  // namespace
}  // namespace clothwind
