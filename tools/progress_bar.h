#ifndef CLOTHWIND_TOOLS_PROGRESS_BAR_H_
#define CLOTHWIND_TOOLS_PROGRESS_BAR_H_

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <mutex>
#include <string>

namespace clothwind::tools {

// Progress of a long verb on stderr, shared by every verb. On a terminal it redraws one line
//   "label [#####.....]  45%  225/500 frames  3.2 sim s/s  ETA 12 s  <note>"
// at most five times a second; otherwise (a log file, a batch scheduler) it prints the same
// text as plain lines, one every `plain_interval` seconds and one at the end, so logs stay short.
// Update is thread-safe (worker threads may call it directly).
class ProgressBar {
 public:
  struct Options {
    std::string label;              // printed first, e.g. "make-dataset"
    std::string unit = "items";     // what `done` counts
    double rate_scale = 1.0;        // the rate shown is done * rate_scale per second ...
    std::string rate_unit;          // ... in this unit (e.g. frame_time and "sim s/s"); "": unit + "/s"
    double plain_interval = 10.0;   // [s] between plain lines when not on a terminal
    std::FILE* stream = stderr;
    int tty = -1;                   // -1: detect (isatty); 0: plain lines; 1: redraw
    int columns = -1;               // the terminal's width; -1: ask it (TIOCGWINSZ, else $COLUMNS, else 80)
  };

  explicit ProgressBar(Options options);
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;

  // Reports that `done` of `total` units are finished; `note` is appended (e.g. the last
  // item's name). Rate and time left are measured from the first report: report (0, total) when
  // the work starts if setup comes before it or units finish in batches (--jobs 16 finishing 16
  // simulations at once). The first report of done >= total prints at once; later ones (work after the
  // last unit, e.g. training's validation, reported as steps/steps with a note) are throttled like
  // the rest, at plain_interval even on a terminal, whose line the first one ended. Returns true,
  // so it can serve as a keep-going callback.
  bool Update(int64_t done, int64_t total, const std::string& note = "");

  // Ends the line on a terminal (call once when done; Update(total, total) also does).
  void Finish();

  // Seconds since construction.
  double Elapsed() const;

 private:
  void Print(int64_t done, int64_t total, const std::string& note, double now);
  int Columns() const;  // the width a redrawn line fits (Options::columns)

  Options o_;
  bool tty_;
  std::mutex mutex_;
  std::chrono::steady_clock::time_point start_;
  double last_print_ = -1e300;  // [s since start]
  bool open_line_ = false;      // a redrawn line is on screen without its newline
  bool reported_last_ = false;  // done >= total was printed once
  // The first report: rate and ETA are measured from it, not from construction, so that the
  // setup before the first unit (listing a folder, loading a model) does not read as the units'
  // pace. Its own line shows "ETA ?": one unit timed with the setup gave "ETA 1 h 41 min" for a
  // re-index that took 1.5 s.
  bool have_first_ = false;
  int64_t first_done_ = 0;
  double first_time_ = 0;  // [s since start]
};

// The line a terminal's bar redraws, fitted to `columns` - 1 characters (a line as wide as the
// terminal, or wider, wraps, and each "\r" redraw then returns to the start of its last row only:
// half-lines piled up on an 80-column terminal, five a second): the note is cut first, then the
// bar narrowed from 30 cells to 10, then the line cut.
// Inputs: label (with its trailing space, or ""), fraction done in [0, 1], text (percent, counts,
//         rate, ETA), note, columns (> 0).
std::string RedrawnLine(const std::string& label, double fraction, const std::string& text, const std::string& note,
                        int columns);

// "12 s", "3 min 05 s", "2 h 04 min": a duration [s] for people.
std::string FormatDuration(double seconds);

}  // namespace clothwind::tools

#endif  // CLOTHWIND_TOOLS_PROGRESS_BAR_H_
