#include "sensors/frame_source_factory.h"

#include "sensors/frame_source_folder.h"
#include "sensors/pixel_format.h"
#include "sensors/v4l2_camera.h"
#include "sensors/v4l2_io.h"
#include "sensors/video_source.h"

namespace clothwind {
namespace sensors {

std::unique_ptr<FrameSource> MakeFrameSource(const FrameSourceOptions& o, Clock* clock, LogFn log,
                                             std::string* error) {
  auto fail = [error](const std::string& why) -> std::unique_ptr<FrameSource> {
    if (error) *error = why;
    return nullptr;
  };
  // At most 1000 Hz: inf went to lround (undefined) in the pacer and the camera's frame interval.
  if (!(o.fps > 0 && o.fps <= 1000)) return fail("fps/rate must be > 0 and <= 1000 Hz, got " + std::to_string(o.fps));
  if (o.source == "v4l2") {
    V4l2Options v;
    v.device = o.path.empty() ? "/dev/video0" : o.path;
    if (!ParsePixelFormat(o.pixel_format, &v.format, error)) return nullptr;
    if (o.width <= 0 || o.height <= 0) {
      return fail("width and height must be > 0 px, got " + std::to_string(o.width) + "x" +
                  std::to_string(o.height));
    }
    if (o.buffers < 2) return fail("buffers must be >= 2, got " + std::to_string(o.buffers));
    // Finite and at most a day: inf or 1e10 overflowed its nanoseconds (INT64_MIN on x86), so the
    // loss deadline was always past and the camera was reopened every 0.25 s.
    if (!(o.timeout_s > 0 && o.timeout_s <= 86400))
      return fail("timeout must be > 0 and <= 86400 s, got " + std::to_string(o.timeout_s));
    v.width = o.width;
    v.height = o.height;
    v.fps = o.fps;
    v.buffers = o.buffers;
    v.timeout_s = o.timeout_s;
    v.auto_exposure = o.auto_exposure;
    v.exposure_absolute = o.exposure_absolute;
    v.gain = o.gain;
    // The syscall wrapper is stateless: one instance serves every camera.
    static SyscallV4l2Io io;
    return std::make_unique<V4l2Camera>(v, &io, clock, std::move(log));
  }
  if (o.source == "video" || o.source == "folder") {
    if (o.path.empty()) return fail("source '" + o.source + "' needs a path");
    if (o.source == "video") return std::make_unique<VideoFileSource>(o.path, o.fps, o.loop, clock);
    return std::make_unique<ImageFolderSource>(o.path, o.fps, o.loop, clock);
  }
  return fail("source '" + o.source + "' is not one of v4l2, video, folder");
}

}  // namespace sensors
}  // namespace clothwind
