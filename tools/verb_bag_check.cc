// clothwind bag-check: is a recorded session bag fit for replay (launch/replay.launch)? Per topic:
// message count, rate, span, header stamps monotonic and near their bag times; camera holes
// longer than the clip buffer's gap tolerance; camera frames the clip buffer can read; anemometer
// sentences decoded. Exit status 1 when the replay would make no labelled clip or would not
// start: a required topic missing, every message of one stamped 0 or far ahead of the bag's time
// (the replay's clock), no camera frame the clip buffer can read, no usable anemometer reading
// (one that decodes, is not flagged void and is a speed of 0..150 m/s, as the clip buffer takes
// them) with a stamp in any clip's label window that arrives before the clip is labelled, no
// stretch of video without holes long enough for a clip, or a topic no replay node reads
// (replay.launch waits for a subscriber on every topic unless wait:=false). What the nodes drop
// one message at a time and go on (stamps that go back, repeat, lie far ahead or are 0, a lone
// frame stamped ahead or behind, an unreadable frame) is a warning naming the first (message
// index and bag time), so a driver's one bad frame must not refuse a field bag; what it costs is
// counted in the holes and the longest stretch without one. camera_info's stamps are not checked:
// the clip buffer copies its calibration and reads no stamp of it.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <std_msgs/Header.h>

#include <clothwind/RawSentence.h>

#include "progress_bar.h"
#include "ros_bridge/clip_conversions.h"
#include "sensors/anemometer_protocol.h"
#include "sensors/wind_reading.h"
#include "verb_registry.h"
#include "usage_error.h"

namespace clothwind::tools {
namespace {

struct BagCheckArgs {
  std::string bag;
  double gap_tolerance = 0.1;  // clip_buffer's ~gap_tolerance [s]
  double max_future = 5.0;     // clip_buffer's ~max_future [s]
  double clip_duration = 1.16; // a clip's first to last frame [s]: 30 frames at 25 fps
  double label_window = 60.0;  // clip_buffer's ~label_window [s]
  // How long after a clip's last frame the clip buffer labels it (its ~label_delay plus the
  // pipeline's wait) [s]: a reading recorded later than that labels nothing.
  double label_delay = 1.5;
  // With no input this long the clip buffer labels its waiting clips with what it holds (its
  // ~flush_after, in wall seconds) [s]; times replay_rate, the bag seconds that pass meanwhile.
  double flush_after = 3.0;
  double replay_rate = 1.0;  // the rate the bag will be played at (rosbag play -r)
};

// The topics replay.launch's nodes read (clip_buffer: the camera's two; the anemometer node in
// topic mode: the raw sentences), by their names without a leading slash.
const char* const kReplayTopics[] = {"camera/image_raw", "camera/camera_info", "anemometer/raw"};
// The type each replayed topic's node subscribes with: another (a CompressedImage recorded as
// camera/image_raw) passed as "ok for replay", and the node never received a message.
const char* ReplayTopicType(const std::string& name) {
  if (name == "camera/image_raw") return "sensor_msgs/Image";
  if (name == "camera/camera_info") return "sensor_msgs/CameraInfo";
  if (name == "anemometer/raw") return "clothwind/RawSentence";
  return "";
}

std::string WithoutLeadingSlash(const std::string& topic) {
  return !topic.empty() && topic[0] == '/' ? topic.substr(1) : topic;
}

struct TopicStats {
  std::string type;
  size_t count = 0;
  double first = NAN, last = NAN, previous = NAN;
  size_t backwards = 0;       // header stamp before the previous one
  std::string first_backwards, first_repeated;  // where the first of each is: "message N (bag time T s)"
  std::optional<double> held;  // a camera frame more than the tolerance back, waiting for the next
  std::optional<double> held_ahead;  // one more than the tolerance ahead, waiting likewise
  std::string held_ahead_where;
  size_t stale = 0;            // such frames the next did not follow: lone stale stamps, dropped
  size_t stale_ahead = 0;      // of them, frames stamped ahead
  std::string first_stale_ahead;
  size_t kept = 0;             // messages on the timeline (not dropped for a 0 or far-ahead stamp)
  std::string first_dropped;   // where the first message stamped 0 or far ahead is
  size_t unreadable = 0;       // camera frames the clip buffer cannot read (ImageView refuses them)
  std::string first_unreadable;
  size_t repeated = 0;        // header stamp equal to the previous one (records of one serial read
                              // share it; camera frames must not: the clip buffer drops them)
  size_t bag_time_off = 0;    // |bag time - header stamp| > 1 ms
  size_t far_from_bag_time = 0;  // header stamp > bag time + max_future: the replay's clock is the
                                 // bag time, and clip_buffer refuses stamps that far ahead of it
                                 // (stamps behind it are fine: a camera's latency)
  size_t zero = 0;            // header stamp 0
  double longest_run = 0.0;   // longest span of stamps without a hole [s]
  double run_start = NAN;
  size_t decoded = 0, undecoded = 0;  // anemometer sentences that give a reading, and that do not
  size_t void_readings = 0;           // decoded, but flagged void or a speed outside 0..150 m/s
  // The readings a clip can be labelled by: (stamp, the camera's data time when the replay
  // delivers it: the latest frame stamp before it in the bag) [s].
  std::vector<std::pair<double, double>> usable;
  std::string first_error;
  size_t holes = 0;           // header stamp intervals > gap tolerance
  double widest = 0.0;        // largest interval [s]
  std::string first_data;     // first raw sentence / image encoding and size
};

// Where a message is, for the warnings: "message N (bag time T s)".
std::string Where(size_t index, double bag_time) {
  char where[96];
  std::snprintf(where, sizeof where, "message %zu (bag time %.3f s)", index, bag_time);
  return where;
}

// Whether the replay's nodes drop a message of this stamp: 0, or more than max_future ahead of
// its bag time (the replay's clock).
bool DroppedStamp(double stamp, double bag_time, double max_future) {
  return stamp == 0 || stamp - bag_time > max_future;
}

void Note(TopicStats& s, double stamp, double bag_time, double gap_tolerance, double max_future, size_t index) {
  ++s.count;
  if (std::fabs(bag_time - stamp) > 1e-3) ++s.bag_time_off;
  const std::string where = Where(index, bag_time);
  // Dropped one at a time by the nodes, which go on: counted, and not on the timeline (one frame
  // stamped 10 s ahead refused a field bag that replays whole).
  if (DroppedStamp(stamp, bag_time, max_future)) {
    ++(stamp == 0 ? s.zero : s.far_from_bag_time);
    if (s.first_dropped.empty()) s.first_dropped = where;
    return;
  }
  if (s.kept++ == 0) {
    s.last = stamp;
    s.first = s.run_start = s.previous = stamp;
    return;
  }
  // Camera frames (a finite tolerance) follow the clip pipeline's rules: a frame a little early is
  // dropped by the resampler (no hole); one more than the tolerance back waits for the next, which
  // either follows it (the stream went back: a new timeline from it, a hole) or does not (a lone
  // stale frame, dropped, the run going on).
  const bool frames = gap_tolerance < 1e9;
  if (frames && s.held) {
    const double held = *s.held;
    s.held.reset();
    if (stamp >= held && stamp - held <= gap_tolerance) {
      ++s.holes;
      s.run_start = s.previous = held;
    } else {
      ++s.stale;
    }
  }
  // One more than the tolerance ahead likewise (ClipPipeline's forward hold): time going on from
  // it confirms a hole; time coming back before it drops it as a lone stale stamp, the run going
  // on. (Counted as a hole, its next frame then read as going back: two holes and a broken run
  // for a frame the clip buffer drops.)
  if (frames && s.held_ahead) {
    const double held = *s.held_ahead;
    s.held_ahead.reset();
    if (stamp > held) {
      ++s.holes;
      s.widest = std::max(s.widest, held - s.previous);
      s.run_start = s.previous = held;
      s.last = std::max(s.last, held);
    } else {
      ++s.stale;
      if (s.stale_ahead++ == 0) s.first_stale_ahead = s.held_ahead_where;
    }
  }
  const double dt = stamp - s.previous;
  if (dt < 0 && s.backwards++ == 0) s.first_backwards = where;
  if (dt == 0 && s.repeated++ == 0) s.first_repeated = where;
  if (frames && dt < -gap_tolerance) {
    s.held = stamp;
    return;
  }
  if (frames && dt > gap_tolerance) {
    s.held_ahead = stamp;
    s.held_ahead_where = where;
    return;
  }
  // On the timeline (a frame held ahead only once the next confirms it: a lone one the clip
  // buffer drops extended the span and the clips' last end).
  s.last = std::max(s.last, stamp);
  if (dt > gap_tolerance) {
    ++s.holes;
    s.run_start = stamp;
  }
  s.widest = std::max(s.widest, dt);
  s.longest_run = std::max(s.longest_run, stamp - s.run_start);
  if (!frames || dt >= 0) s.previous = stamp;
}

// Counts one message into its topic's stats (ros::Exception when its bytes do not deserialise).
//   data_time  the latest camera frame stamp before this message (-inf before the first)
void NoteMessage(const rosbag::MessageInstance& m, TopicStats& s, double t, const BagCheckArgs& a,
                 sensors::AnemometerDecoder& decoder, size_t index, double data_time) {
  if (auto img = m.instantiate<sensor_msgs::Image>()) {
    if (s.first_data.empty())
      s.first_data = img->encoding + " " + Num(img->width) + "x" + Num(img->height) +
                     " frame " + img->header.frame_id;
    // As the clip buffer reads it (an encoding it cannot convert, a step or data too short): a
    // frame it drops, which "ok for replay" passed when no frame could be read.
    try {
      cv::Mat view;
      sensors::ClipSourceEncoding encoding;
      ros_bridge::ImageView(*img, &view, &encoding);
    } catch (const std::exception& e) {
      ++s.count;
      if (s.unreadable++ == 0)
        s.first_unreadable = Where(index, t) + ": " + e.what();
      return;
    }
    Note(s, img->header.stamp.toSec(), t, a.gap_tolerance, a.max_future, index);
  } else if (auto info = m.instantiate<sensor_msgs::CameraInfo>()) {
    // By its bag time: the clip buffer copies the calibration and reads no stamp of it.
    Note(s, t, t, 1e9, a.max_future, index);
    if (s.first_data.empty())
      s.first_data = Num(info->width) + "x" + Num(info->height) + " " + info->distortion_model;
  } else if (auto raw = m.instantiate<clothwind::RawSentence>()) {
    Note(s, raw->header.stamp.toSec(), t, 1e9, a.max_future, index);
    if (s.first_data.empty()) s.first_data = raw->data + " (" + raw->protocol + ")";
    // As the anemometer node in topic mode reads them (a bad checksum labels no clip).
    const sensors::ParseResult r = decoder.Decode(std::string(raw->data.begin(), raw->data.end()));
    if (r.status == sensors::ParseStatus::kOk) {
      ++s.decoded;
      // As the clip buffer's labeller takes a reading (ToLabelReading): a void one (NMEA status V,
      // a Gill error code) or an impossible speed labels nothing.
      const double v = r.reading.speed;
      const double stamp = raw->header.stamp.toSec();
      if (DroppedStamp(stamp, t, a.max_future)) {
        // dropped by the anemometer node: no label from it
      } else if (r.reading.valid && std::isfinite(v) && v >= 0 && v <= sensors::kMaxPlausibleWindSpeed) {
        s.usable.emplace_back(stamp, data_time);
      } else {
        ++s.void_readings;
      }
    } else if (r.status != sensors::ParseStatus::kNotWind) {
      ++s.undecoded;
      if (s.first_error.empty()) s.first_error = r.error;
    }
  } else {
    Note(s, t, t, 1e9, a.max_future, index);  // any other message: bag time only
  }
}

int Check(const BagCheckArgs& a);

// The bag's errors name it and what to do: rosbag's own ("Error reading from file: wanted 4
// bytes, read 0 bytes") named neither the file nor, for a recording cut short, the repair.
int Run(const BagCheckArgs& a) {
  auto in = [](double v, double hi) { return v > 0 && v <= hi; };  // NaN passed CLI's range checks
  if (!in(a.gap_tolerance, 3600))
    throw UsageError("--gap-tolerance must be in (0, 3600] s, got " + Num(a.gap_tolerance));
  if (!in(a.max_future, 86400))
    throw UsageError("--max-future must be in (0, 86400] s, got " + Num(a.max_future));
  if (!in(a.clip_duration, 3600))
    throw UsageError("--clip-duration must be in (0, 3600] s, got " + Num(a.clip_duration));
  if (!in(a.label_window, 86400))
    throw UsageError("--label-window must be in (0, 86400] s, got " + Num(a.label_window));
  if (!(a.label_delay >= 0 && a.label_delay <= 86400))
    throw UsageError("--label-delay must be in [0, 86400] s, got " + Num(a.label_delay));
  if (!in(a.flush_after, 86400))
    throw UsageError("--flush-after must be in (0, 86400] s, got " + Num(a.flush_after));
  if (!in(a.replay_rate, 1000))
    throw UsageError("--replay-rate must be in (0, 1000], got " + Num(a.replay_rate));
  {
    // A file that is no bag at all: rosbag says "Error reading version line", which the repair
    // hint below also matched.
    std::FILE* f = std::fopen(a.bag.c_str(), "rb");
    char head[13] = {};
    const size_t n = f ? std::fread(head, 1, 12, f) : 0;
    if (f) std::fclose(f);
    if (f && (n < 9 || std::string(head, 9) != "#ROSBAG V"))  // V2.0; rosbag still reads V1.2
      throw std::runtime_error(a.bag + ": not a readable bag: not a rosbag file (it does not begin with \"#ROSBAG V\")");
  }
  try {
    return Check(a);
  } catch (const rosbag::BagException& e) {
    const std::string what = e.what();
    // A recording cut short says "unindexed", or fails reading its index ("Error reading from
    // file"): both are what `rosbag reindex` repairs.
    const bool cut_short = what.find("unindexed") != std::string::npos || what.find("Error reading") != std::string::npos;
    throw std::runtime_error(a.bag + ": not a readable bag (" + what + ")" +
                             (cut_short ? "; a recording cut short can be repaired with `rosbag reindex`" : ""));
  }
}

int Check(const BagCheckArgs& a) {
  rosbag::Bag bag;
  bag.open(a.bag, rosbag::bagmode::Read);
  rosbag::View view(bag);
  std::map<std::string, TopicStats> topics;  // by name without a leading slash
  for (const auto* c : view.getConnections()) topics[WithoutLeadingSlash(c->topic)].type = c->datatype;
  sensors::AnemometerDecoder decoder;
  size_t index = 0;
  double last_input = NAN;  // bag time of the last camera frame or anemometer record
  double flushed = -std::numeric_limits<double>::infinity();  // camera data time at the last flush
  // A field session of hours is gigabytes, read for minutes: progress on stderr for bags of
  // 256 MiB and more (small ones, a test's or make run's, stay quiet).
  std::error_code size_error;
  std::unique_ptr<ProgressBar> bar;
  if (std::filesystem::file_size(a.bag, size_error) >= (256u << 20) && !size_error) {
    ProgressBar::Options o;
    o.label = "bag-check";
    o.unit = "messages";
    bar = std::make_unique<ProgressBar>(o);
  }
  const size_t total = bar ? view.size() : 0;
  // Every topic is in the map from the connections on, so this stays valid (end() when none).
  const auto camera_topic = topics.find("camera/image_raw");
  for (const rosbag::MessageInstance& m : view) {
    const std::string topic = WithoutLeadingSlash(m.getTopic());
    TopicStats& s = topics[topic];
    const double t = m.getTime().toSec();
    ++index;
    if (bar) bar->Update(static_cast<int64_t>(index), static_cast<int64_t>(total));
    // A message whose bytes do not deserialise (a length field that overruns) threw a bare
    // "Buffer Overrun" naming nothing; messages beyond 1 GiB are refused before reading.
    if (m.size() > (1u << 30))
      throw std::runtime_error(a.bag + ": message " + Num(index) + " of the bag (on " + m.getTopic() + ")" + " is " +
                               Num(m.size()) + " bytes (a corrupt record?)");
    const double camera_time = camera_topic != topics.end() && camera_topic->second.kept > 0
                                   ? camera_topic->second.last
                                   : -std::numeric_limits<double>::infinity();
    // A pause in the input longer than flush_after: the clips waiting then went out with the
    // readings held, and a reading that comes after labels none of them.
    if (topic == "camera/image_raw" || topic == "anemometer/raw") {
      if (std::isfinite(last_input) && t - last_input > a.flush_after * a.replay_rate) flushed = camera_time;
      last_input = t;
    }
    const double data_time = std::max(camera_time, flushed + a.label_delay + 1e-6);
    try {
      NoteMessage(m, s, t, a, decoder, index, data_time);
    } catch (const ros::Exception& e) {
      throw std::runtime_error(a.bag + ": message " + Num(index) + " of the bag (on " + m.getTopic() + ")" + " (" +
                               m.getDataType() + ", bag time " + Num(t) + " s) does not deserialise: " +
                               e.what());
    }
  }
  bag.close();
  if (bar) bar->Finish();
  std::printf("%s\n", a.bag.c_str());
  std::printf("  %-22s %-28s %7s %8s %8s %6s %6s %6s %6s  %s\n", "topic", "type", "count", "rate Hz", "span s",
              "back", "same", "holes", "bagt", "first");
  std::vector<std::string> problems, warnings;  // no problems: ok for replay
  auto fail = [&](const std::string& why) { problems.push_back(why); };
  auto warn = [&](const std::string& why) { warnings.push_back(why); };
  for (const auto& [name, s] : topics) {
    const double span = s.count > 1 ? s.last - s.first : 0.0;
    std::printf("  %-22s %-28s %7zu %8.2f %8.2f %6zu %6zu %6zu %6zu  %s\n", name.c_str(), s.type.c_str(), s.count,
                span > 0 ? (s.count - 1) / span : 0.0, span, s.backwards, s.repeated, s.holes, s.bag_time_off,
                s.first_data.c_str());
    const bool camera = name.find("image") != std::string::npos;
    if (s.backwards > 0)
      warn(name + ": " + Num(s.backwards) + " header stamps go back (the first at " + s.first_backwards +
           (camera ? "; a frame a little early is dropped; one more than the gap tolerance back is dropped as stale (" +
                         Num(s.stale - s.stale_ahead) + " here) unless the next follows it, a new timeline)"
                   : ")"));
    if (camera && s.stale_ahead > 0)
      warn(name + ": " + Num(s.stale_ahead) + " lone frames stamped more than the gap tolerance ahead of "
           "the next (the first at " + s.first_stale_ahead + "); the clip buffer drops them as stale");
    if (camera && s.repeated > 0)
      warn(name + ": " + Num(s.repeated) + " frames repeat a stamp (the first at " + s.first_repeated +
           "; the clip buffer drops them)");
    const bool replayed = std::find(std::begin(kReplayTopics), std::end(kReplayTopics), name) != std::end(kReplayTopics);
    if (!replayed) {
      fail(name + ": no replay node reads it, and replay.launch waits for a subscriber on every topic "
                  "(play it with wait:=false)");
      continue;
    }
    if (s.type != ReplayTopicType(name))
      fail(name + ": recorded as " + s.type + ", the replay subscribes to it as " + ReplayTopicType(name) +
           " (it would receive nothing)");
    // Every message dropped for its stamp: the topic is as good as missing. Some: said, as the
    // nodes drop them one at a time and go on.
    const size_t dropped = s.zero + s.far_from_bag_time;
    if (dropped > 0) {
      const std::string what = name + ": " + Num(s.zero) + " messages stamped 0 and " +
                               Num(s.far_from_bag_time) + " more than " + Num(a.max_future) +
                               " s ahead of their bag time (the replay's clock; another time base?), the first at " +
                               s.first_dropped + "; the nodes drop them";
      if (dropped == s.count) fail(what + ": every message"); else warn(what);
    }
    if (s.unreadable > 0) {
      const std::string what = name + ": " + Num(s.unreadable) + " of " + Num(s.count) +
                               " frames the clip buffer cannot read (the first, " + s.first_unreadable + ")";
      if (s.unreadable == s.count) fail(what); else warn(what);
    }
  }
  const auto camera = topics.find("camera/image_raw"), wind = topics.find("anemometer/raw");
  for (const char* required : {"camera/image_raw", "anemometer/raw"})
    if (!topics.count(required)) fail(std::string("missing: ") + required + " (replay.launch needs it)");
  if (camera != topics.end() && camera->second.count > 0 && camera->second.longest_run < a.clip_duration)
    fail("camera/image_raw: no stretch of frames without a hole (> " + Num(a.gap_tolerance) +
         " s) lasts a clip's " + Num(a.clip_duration) + " s (longest " +
         Num(camera->second.longest_run) + " s)");
  if (wind != topics.end() && wind->second.count > 0 && wind->second.decoded == 0)
    fail("anemometer/raw: no sentence gives a wind reading (" + Num(wind->second.undecoded) +
         " refused, the first: " + wind->second.first_error + ")");
  else if (wind != topics.end() && wind->second.decoded > 0 && wind->second.usable.empty())
    fail("anemometer/raw: no reading the clip buffer can label with: " + Num(wind->second.void_readings) +
         " void (the instrument's status V or error code, or a speed outside 0..150 m/s), the rest stamped 0 or far "
         "ahead (dropped by the anemometer node)");
  // A clip ending at e is labelled by the usable readings stamped in [e - label window, e] that
  // the replay has delivered when the clip goes out, once the camera's data time passes e +
  // label_delay; clips end from the first frame + a clip's duration to the last frame. So a
  // reading stamped r and delivered at data time D labels a clip when some e in
  // [max(r, first + duration, D - delay), min(r + window, last)] exists (a camera and an
  // anemometer equally late in the bag are no later to each other). (Comparing only the earliest
  // and latest usable stamps passed a bag with usable readings before and after the video and only
  // void ones during it; stamps alone passed one whose readings were recorded 40 s late, and no
  // clip was labelled.)
  const auto labels_a_clip = [&](const std::vector<std::pair<double, double>>& usable) {
    for (const auto& [r, delivered] : usable) {
      const double lo = std::max({r, camera->second.first + a.clip_duration, delivered - a.label_delay});
      if (lo <= std::min(r + a.label_window, camera->second.last)) return true;
    }
    return false;
  };
  if (camera != topics.end() && wind != topics.end() && camera->second.kept > 0 && !wind->second.usable.empty() &&
      !labels_a_clip(wind->second.usable))
    fail("no usable anemometer/raw reading's stamp falls in a clip's label window (the " + Num(a.label_window) +
         " s up to its last frame, over camera/image_raw's stamps) and is recorded before that clip is labelled (" +
         Num(a.label_delay) + " s after its last frame): no clip gets a label");
  std::printf("  (back: header stamps going back; same: equal to the previous (fine for anemometer records of "
              "one serial read, not for camera frames); holes: camera intervals > %.3f s, which break clips; "
              "bagt: bag time != header stamp)\n",
              a.gap_tolerance);
  if (wind != topics.end() && wind->second.undecoded > 0)
    std::printf("  anemometer/raw: %zu of %zu sentences refused (the first: %s)\n", wind->second.undecoded,
                wind->second.count, wind->second.first_error.c_str());
  if (wind != topics.end() && wind->second.void_readings > 0)
    std::printf("  anemometer/raw: %zu of %zu readings void or out of range (no label from them)\n",
                wind->second.void_readings, wind->second.count);
  for (const std::string& w : warnings) std::printf("  warning: %s\n", w.c_str());
  for (const std::string& p : problems) std::printf("  NOT ok: %s\n", p.c_str());
  std::printf("  %s\n", problems.empty() ? "ok for replay" : "NOT ok for replay");
  return problems.empty() ? 0 : 1;
}

const VerbRegistrar kRegistrar{"bag-check", [](CLI::App& app) -> std::function<int()> {
  auto args = std::make_shared<BagCheckArgs>();
  auto* sub = app.add_subcommand("bag-check", "check a session bag for replay (topics, rates, stamps, holes)");
  // (A missing bag is the work failing, status 1, named by rosbag, as every verb's missing input.)
  sub->add_option("bag", args->bag, "session bag")->required();
  sub->add_option("--gap-tolerance", args->gap_tolerance, "camera hole that breaks a clip [s] (clip_buffer's)")
      ->capture_default_str();
  sub->add_option("--max-future", args->max_future,
                  "largest header stamp - bag time [s] (clip_buffer refuses stamps this far ahead of the clock)")
      ->capture_default_str();
  sub->add_option("--clip-duration", args->clip_duration,
                  "first to last frame of a clip [s]; some stretch without holes must last this long")
      ->capture_default_str();
  sub->add_option("--label-window", args->label_window,
                  "a clip is labelled by the anemometer readings this long [s] up to its last frame (clip_buffer's)")
      ->capture_default_str();
  sub->add_option("--label-delay", args->label_delay,
                  "a clip is labelled this long [s] after its last frame (clip_buffer's); a reading recorded later "
                  "labels nothing")
      ->capture_default_str();
  sub->add_option("--flush-after", args->flush_after,
                  "with no input this long [s, wall] the clip buffer labels its waiting clips (clip_buffer's)")
      ->capture_default_str();
  sub->add_option("--replay-rate", args->replay_rate,
                  "the rate the bag will be played at (rosbag play -r; replay.launch rate:=): how much bag time "
                  "--flush-after spans")
      ->capture_default_str();
  return [args] { return Run(*args); };
}};

}  // namespace
}  // namespace clothwind::tools
