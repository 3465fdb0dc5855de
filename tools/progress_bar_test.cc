#include "progress_bar.h"

#include <cstdio>
#include <string>

#include <gtest/gtest.h>

namespace clothwind::tools {
namespace {

// What a bar wrote to its stream.
std::string Written(std::FILE* f) {
  std::fflush(f);
  std::rewind(f);
  std::string text;
  char buf[4096];
  for (size_t n; (n = std::fread(buf, 1, sizeof buf, f)) > 0;) text.append(buf, n);
  return text;
}

size_t Count(const std::string& text, char c) {
  size_t n = 0;
  for (char x : text) n += x == c;
  return n;
}

// Training reports its validation as steps/steps with a note, after the last step: each such
// report printed a line (hundreds an epoch in a log file). Only the first report of the end prints
// at once; the rest wait out the interval like any other.
TEST(ProgressBar, ReportsAfterTheEndAreThrottledLikeTheRest) {
  for (int tty : {0, 1}) {
    SCOPED_TRACE(tty ? "terminal" : "log file");
    std::FILE* f = std::tmpfile();
    ASSERT_NE(f, nullptr);
    ProgressBar::Options o;
    o.label = "train";
    o.stream = f;
    o.tty = tty;
    o.plain_interval = 3600;
    ProgressBar bar(o);
    for (int step = 0; step <= 50; ++step) bar.Update(step, 50, "loss 1");
    for (int val = 1; val <= 300; ++val) bar.Update(50, 50, "validating " + std::to_string(val) + "/300");
    bar.Finish();
    const std::string text = Written(f);
    std::fclose(f);
    // One line (the first report) and the end (done >= total) once.
    EXPECT_EQ(Count(text, '\n'), tty ? 1u : 2u) << text;
    EXPECT_EQ(text.find("validating"), std::string::npos) << text;
    EXPECT_NE(text.find("took"), std::string::npos) << text;
  }
}

TEST(ProgressBar, FormatsDurationsForPeople) {
  EXPECT_EQ(FormatDuration(12.4), "12 s");
  EXPECT_EQ(FormatDuration(185), "3 min 05 s");
  EXPECT_EQ(FormatDuration(7440), "2 h 04 min");
  EXPECT_EQ(FormatDuration(-1), "?");
}

}  // namespace
}  // namespace clothwind::tools
