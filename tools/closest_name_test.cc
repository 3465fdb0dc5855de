#include "closest_name.h"

#include <gtest/gtest.h>

namespace clothwind::tools {
namespace {

TEST(EditDistance, CountsInsertionsDeletionsAndSubstitutions) {
  EXPECT_EQ(EditDistance("", ""), 0u);
  EXPECT_EQ(EditDistance("eval", "eval"), 0u);
  EXPECT_EQ(EditDistance("make-datset", "make-dataset"), 1u);  // one insertion
  EXPECT_EQ(EditDistance("trian", "train"), 2u);               // a swap is two substitutions
  EXPECT_EQ(EditDistance("kitten", "sitting"), 3u);
  EXPECT_EQ(EditDistance("abc", ""), 3u);
}

TEST(ClosestName, SuggestsANearNameAndNothingForAFarOne) {
  const std::vector<std::string> verbs = {"bag-check", "eval", "make-dataset", "make-session", "render", "train"};
  EXPECT_EQ(ClosestName("make-datset", verbs), "make-dataset");
  EXPECT_EQ(ClosestName("bag-chek", verbs), "bag-check");
  EXPECT_EQ(ClosestName("trian", verbs), "train");
  EXPECT_EQ(ClosestName("evl", verbs), "eval");
  EXPECT_EQ(ClosestName("simulate-everything", verbs), "");
  EXPECT_EQ(ClosestName("x", verbs), "");
}

}  // namespace
}  // namespace clothwind::tools
