#include "progress_bar.h"

#include <chrono>
#include <cstdio>
#include <string>
#include <thread>

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

// The pace is measured from the first report: the setup before it (300 ms here) read as the
// first unit's time, and a first line of "ETA 4 min 59 s" for work of a fraction of a second.
TEST(ProgressBar, PaceIsMeasuredFromTheFirstReport) {
  std::FILE* f = std::tmpfile();
  ASSERT_NE(f, nullptr);
  ProgressBar::Options o;
  o.stream = f;
  o.tty = 0;
  o.plain_interval = 0;
  ProgressBar bar(o);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  bar.Update(1, 1000);
  const std::string first = Written(f);
  EXPECT_NE(first.find("? items/s  ETA ?"), std::string::npos) << first;
  std::this_thread::sleep_for(std::chrono::milliseconds(2));
  bar.Update(2, 1000);
  const std::string second = Written(f).substr(first.size());
  std::fclose(f);
  // 998 units at the pace of the last one (a few ms, however loaded the machine): seconds, not
  // the 998 x 0.3 s the setup implied.
  EXPECT_EQ(second.find("ETA ?"), std::string::npos) << second;
  EXPECT_EQ(second.find(" min"), std::string::npos) << second;
  EXPECT_EQ(second.find(" h "), std::string::npos) << second;
}

// A redrawn line fits the terminal: 102-108 characters on an 80-column one wrapped, and each
// redraw returned to the start of its last row only (half-lines piled up, five a second). The note
// goes first, then the bar narrows, then the line is cut; a wide terminal shows it all.
TEST(ProgressBar, ARedrawnLineFitsTheTerminal) {
  const std::string text = " 38%  5/13 batches  44.4 clips/s  ETA 3 min 10 s";
  const std::string note = "loss 0.1234, validating 120/300 clip runs";
  const std::string wide = RedrawnLine("train epoch 1/20 ", 0.38, text, note, 200);
  EXPECT_EQ(wide, "train epoch 1/20 [###########...................] " + text + "  " + note);
  for (int columns : {120, 100, 80, 60, 40, 10, 1}) {
    const std::string fitted = RedrawnLine("train epoch 1/20 ", 0.38, text, note, columns);
    EXPECT_LE(fitted.size(), static_cast<size_t>(std::max(columns - 1, 1))) << columns << ": " << fitted;
    if (columns >= 40) {
      EXPECT_EQ(fitted.rfind("train epoch 1/20 [", 0), 0u) << fitted;
    }
  }
  // At 80 columns the note is dropped before the bar narrows: the counts and ETA stay whole.
  const std::string eighty = RedrawnLine("train epoch 1/20 ", 0.38, text, note, 80);
  EXPECT_NE(eighty.find("ETA 3 min 10 s"), std::string::npos) << eighty;
  // Through the bar, at a width given.
  std::FILE* f = std::tmpfile();
  ASSERT_NE(f, nullptr);
  ProgressBar::Options o;
  o.label = "make-dataset";
  o.unit = "simulations";
  o.stream = f;
  o.tty = 1;
  o.columns = 80;
  ProgressBar bar(o);
  bar.Update(0, 3, "a note long enough to wrap an eighty-column terminal if it were printed whole, and more");
  bar.Finish();
  std::string written = Written(f);
  std::fclose(f);
  const size_t start = written.find('\r'), end = written.find("\033[K");
  ASSERT_NE(start, std::string::npos);
  ASSERT_NE(end, std::string::npos);
  EXPECT_LE(end - start - 1, 79u) << written;
}

TEST(ProgressBar, FormatsDurationsForPeople) {
  EXPECT_EQ(FormatDuration(12.4), "12 s");
  EXPECT_EQ(FormatDuration(185), "3 min 05 s");
  EXPECT_EQ(FormatDuration(7440), "2 h 04 min");
  EXPECT_EQ(FormatDuration(-1), "?");
}

}  // namespace
}  // namespace clothwind::tools
