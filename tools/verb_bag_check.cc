// clothwind bag-check: is a recorded session bag fit for replay? Per topic: message count, rate,
// span, header stamps monotonic and equal to bag times; camera holes longer than the clip buffer's
// gap tolerance; anemometer sentences parsed. Exit status 1 when a required topic is missing or
// stamps go backwards.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <std_msgs/Header.h>

#include <clothwind/RawSentence.h>

#include "verb_registry.h"

namespace clothwind::tools {
namespace {

struct BagCheckArgs {
  std::string bag;
  double gap_tolerance = 0.1;
};

struct TopicStats {
  std::string type;
  size_t count = 0;
  double first = NAN, last = NAN, previous = NAN;
  size_t backwards = 0;       // header stamp before the previous one
  size_t repeated = 0;        // header stamp equal to the previous one (records of one serial read
                              // share it; camera frames must not: the clip buffer drops them)
  size_t bag_time_off = 0;    // |bag time - header stamp| > 1 ms
  size_t holes = 0;           // header stamp intervals > gap tolerance
  double widest = 0.0;        // largest interval [s]
  std::string first_data;     // first raw sentence / image encoding and size
};

void Note(TopicStats& s, double stamp, double bag_time, double gap_tolerance) {
  if (s.count == 0) s.first = stamp;
  if (s.count > 0) {
    const double dt = stamp - s.previous;
    if (dt < 0) ++s.backwards;
    if (dt == 0) ++s.repeated;
    if (dt > gap_tolerance) ++s.holes;
    s.widest = std::max(s.widest, dt);
  }
  if (std::fabs(bag_time - stamp) > 1e-3) ++s.bag_time_off;
  s.previous = stamp;
  s.last = std::max(std::isnan(s.last) ? stamp : s.last, stamp);
  ++s.count;
}

int Check(const BagCheckArgs& a);

// The bag's errors name it and what to do: rosbag's own ("Error reading from file: wanted 4
// bytes, read 0 bytes") named neither the file nor, for a recording cut short, the repair.
int Run(const BagCheckArgs& a) {
  if (!(a.gap_tolerance > 0 && a.gap_tolerance <= 3600))  // NaN passed CLI's range checks
    throw std::invalid_argument("--gap-tolerance must be in (0, 3600] s, got " + std::to_string(a.gap_tolerance));
  try {
    return Check(a);
  } catch (const rosbag::BagException& e) {
    const std::string what = e.what();
    throw std::runtime_error(a.bag + ": not a readable bag (" + what + ")" +
                             (what.find("unindexed") != std::string::npos
                                  ? "; a recording cut short can be repaired with `rosbag reindex`"
                                  : ""));
  }
}

int Check(const BagCheckArgs& a) {
  rosbag::Bag bag;
  bag.open(a.bag, rosbag::bagmode::Read);
  rosbag::View view(bag);
  std::map<std::string, TopicStats> topics;
  for (const auto* c : view.getConnections()) topics[c->topic].type = c->datatype;
  for (const rosbag::MessageInstance& m : view) {
    TopicStats& s = topics[m.getTopic()];
    const double t = m.getTime().toSec();
    if (auto img = m.instantiate<sensor_msgs::Image>()) {
      Note(s, img->header.stamp.toSec(), t, a.gap_tolerance);
      if (s.first_data.empty())
        s.first_data = img->encoding + " " + std::to_string(img->width) + "x" + std::to_string(img->height) +
                       " frame " + img->header.frame_id;
    } else if (auto info = m.instantiate<sensor_msgs::CameraInfo>()) {
      Note(s, info->header.stamp.toSec(), t, 1e9);
      if (s.first_data.empty())
        s.first_data = std::to_string(info->width) + "x" + std::to_string(info->height) + " " + info->distortion_model;
    } else if (auto raw = m.instantiate<clothwind::RawSentence>()) {
      Note(s, raw->header.stamp.toSec(), t, 1e9);
      if (s.first_data.empty()) s.first_data = raw->data + " (" + raw->protocol + ")";
    } else {
      Note(s, t, t, 1e9);  // any other message: bag time only
    }
  }
  bag.close();
  std::printf("%s\n", a.bag.c_str());
  std::printf("  %-22s %-28s %7s %8s %8s %6s %6s %6s %6s  %s\n", "topic", "type", "count", "rate Hz", "span s",
              "back", "same", "holes", "bagt", "first");
  bool ok = true;
  for (const auto& [name, s] : topics) {
    const double span = s.count > 1 ? s.last - s.first : 0.0;
    std::printf("  %-22s %-28s %7zu %8.2f %8.2f %6zu %6zu %6zu %6zu  %s\n", name.c_str(), s.type.c_str(), s.count,
                span > 0 ? (s.count - 1) / span : 0.0, span, s.backwards, s.repeated, s.holes, s.bag_time_off,
                s.first_data.c_str());
    const bool camera = name.find("image") != std::string::npos;
    ok = ok && s.backwards == 0 && (!camera || s.repeated == 0);
  }
  for (const char* required : {"camera/image_raw", "anemometer/raw"}) {
    const bool found = topics.count(required) || topics.count(std::string("/") + required);
    if (!found) std::printf("  missing: %s (replay.launch needs it)\n", required);
    ok = ok && found;
  }
  std::printf("  (back: header stamps going back; same: equal to the previous (fine for anemometer records of "
              "one serial read, not for camera frames); holes: camera intervals > %.3f s, which break clips; "
              "bagt: bag time != header stamp)\n  %s\n",
              a.gap_tolerance, ok ? "ok for replay" : "NOT ok for replay");
  return ok ? 0 : 1;
}

const VerbRegistrar kRegistrar{"bag-check", [](CLI::App& app) -> std::function<int()> {
  auto args = std::make_shared<BagCheckArgs>();
  auto* sub = app.add_subcommand("bag-check", "Check a session bag for replay (topics, rates, stamps, holes)");
  sub->add_option("bag", args->bag, "session bag")->required()->check(CLI::ExistingFile);
  sub->add_option("--gap-tolerance", args->gap_tolerance, "camera hole that breaks a clip [s]")
      ->capture_default_str();
  return [args] { return Run(*args); };
}};

}  // namespace
}  // namespace clothwind::tools
