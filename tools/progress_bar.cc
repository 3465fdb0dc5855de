#include "progress_bar.h"

#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace clothwind::tools {

ProgressBar::ProgressBar(Options options)
    : o_(std::move(options)),
      tty_(o_.tty >= 0 ? o_.tty == 1 : ::isatty(::fileno(o_.stream)) == 1),
      start_(std::chrono::steady_clock::now()) {
  if (o_.rate_unit.empty()) o_.rate_unit = o_.unit + "/s";
}

double ProgressBar::Elapsed() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

bool ProgressBar::Update(int64_t done, int64_t total, const std::string& note) {
  std::lock_guard<std::mutex> lock(mutex_);
  const double now = Elapsed();
  if (!have_first_) {
    have_first_ = true;
    first_done_ = done;
    first_time_ = now;
  }
  const bool last = done >= total;
  // Every report of done >= total used to print at once: training's validation, reported as
  // steps/steps, printed a line per batch (hundreds an epoch).
  const bool first_last = last && !reported_last_;
  const double interval = tty_ && !reported_last_ ? 0.2 : o_.plain_interval;
  if (!first_last && now - last_print_ < interval) return true;
  if (last) reported_last_ = true;
  last_print_ = now;
  Print(done, total, note, now);
  return true;
}

void ProgressBar::Print(int64_t done, int64_t total, const std::string& note, double now) {
  // Paced since the first report while under way; the end reports the whole run's average.
  const bool paced = done > first_done_ && now > first_time_;
  const bool end = done >= total;
  const double units_per_s = end ? (now > 0 ? done / now : 0.0)
                                 : (paced ? (done - first_done_) / (now - first_time_) : 0.0);
  const double eta = units_per_s > 0 ? (total - done) / units_per_s : 0.0;
  char rate[48];
  if (end || paced)
    std::snprintf(rate, sizeof(rate), "%.3g", units_per_s * o_.rate_scale);  // in rate_unit
  else
    std::snprintf(rate, sizeof(rate), "?");
  const int percent = total > 0 ? static_cast<int>(100 * std::min(done, total) / total) : 100;
  char text[256];
  std::snprintf(text, sizeof(text), "%3d%%  %lld/%lld %s  %s %s  %s %s", percent,
                static_cast<long long>(done), static_cast<long long>(total), o_.unit.c_str(),
                rate, o_.rate_unit.c_str(), end ? "took" : "ETA",
                end ? FormatDuration(now).c_str() : (units_per_s > 0 ? FormatDuration(eta).c_str() : "?"));
  const std::string label = o_.label.empty() ? "" : o_.label + " ";
  if (tty_) {
    const double fraction = total > 0 ? static_cast<double>(std::min(done, total)) / total : 1.0;
    std::fprintf(o_.stream, "\r%s\033[K", RedrawnLine(label, fraction, text, note, Columns()).c_str());
    open_line_ = done < total;
    if (!open_line_) std::fprintf(o_.stream, "\n");
  } else {
    std::fprintf(o_.stream, "%s%s  %s\n", label.c_str(), text, note.c_str());
  }
  std::fflush(o_.stream);
}

int ProgressBar::Columns() const {
  if (o_.columns > 0) return o_.columns;
  winsize size{};
  if (::ioctl(::fileno(o_.stream), TIOCGWINSZ, &size) == 0 && size.ws_col > 0) return size.ws_col;
  const char* env = std::getenv("COLUMNS");
  const int columns = env ? std::atoi(env) : 0;
  return columns > 0 ? columns : 80;
}

std::string RedrawnLine(const std::string& label, double fraction, const std::string& text, const std::string& note,
                        int columns) {
  const size_t room = static_cast<size_t>(std::max(columns - 1, 1));
  auto line = [&](int cells, const std::string& tail) {
    const int filled = static_cast<int>(cells * std::clamp(fraction, 0.0, 1.0));
    return label + "[" + std::string(filled, '#') + std::string(cells - filled, '.') + "] " + text +
           (tail.empty() ? "" : "  " + tail);
  };
  std::string full = line(30, note);
  if (full.size() <= room) return full;
  const std::string bare = line(30, "");
  if (bare.size() + 2 < room) return full.substr(0, room);  // the note cut
  for (int cells = 29; cells >= 10; --cells)
    if (line(cells, "").size() <= room) return line(cells, "");
  return line(10, "").substr(0, room);
}

void ProgressBar::Finish() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (tty_ && open_line_) std::fprintf(o_.stream, "\n");
  open_line_ = false;
}

std::string FormatDuration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "?";
  char text[64];
  const long long s = std::llround(seconds);
  if (seconds < 60) {
    std::snprintf(text, sizeof(text), "%.0f s", seconds);
  } else if (s < 3600) {
    std::snprintf(text, sizeof(text), "%lld min %02lld s", s / 60, s % 60);
  } else {
    std::snprintf(text, sizeof(text), "%lld h %02lld min", s / 3600, (s % 3600) / 60);
  }
  return text;
}

}  // namespace clothwind::tools
