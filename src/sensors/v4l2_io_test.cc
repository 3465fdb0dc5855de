// The real system-call path. Without a camera these check the failure paths against ordinary
// files; with CLOTHWIND_TEST_V4L2_DEVICE=/dev/videoN set they capture from that camera.
#include "sensors/v4l2_io.h"

#include <fcntl.h>
#include <linux/videodev2.h>
#include <poll.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdlib>

#include <gtest/gtest.h>

#include "sensors/v4l2_camera.h"

namespace clothwind {
namespace sensors {
namespace {

TEST(SyscallV4l2IoTest, NonV4l2FileFailsQueryCap) {
  SyscallV4l2Io io;
  const int fd = io.Open("/dev/null");
  ASSERT_GE(fd, 0);
  v4l2_capability cap{};
  EXPECT_EQ(io.Ioctl(fd, VIDIOC_QUERYCAP, &cap), -1);
  EXPECT_EQ(errno, ENOTTY);
  EXPECT_EQ(io.Mmap(4096, fd, 0), MAP_FAILED);
  EXPECT_EQ(io.Close(fd), 0);
  EXPECT_EQ(io.Close(fd), -1);
  EXPECT_EQ(errno, EBADF);
}

TEST(SyscallV4l2IoTest, PollTimesOutOnASilentDescriptor) {
  SyscallV4l2Io io;
  int pipe_fds[2];
  ASSERT_EQ(pipe(pipe_fds), 0);
  short revents = -1;
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_EQ(io.Poll(pipe_fds[0], 30, &revents), 0);
  const double waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_GE(waited, 0.025);
  EXPECT_EQ(revents, 0);
  ASSERT_EQ(write(pipe_fds[1], "x", 1), 1);
  EXPECT_EQ(io.Poll(pipe_fds[0], 1000, &revents), 1);
  EXPECT_TRUE(revents & POLLIN);
  close(pipe_fds[0]);
  close(pipe_fds[1]);
}

TEST(SyscallV4l2IoTest, CameraReportsMissingAndNonVideoDevices) {
  SyscallV4l2Io io;
  SystemClock clock;
  V4l2Options missing;
  missing.device = "/dev/clothwind-no-such-video";
  V4l2Camera absent(missing, &io, &clock);
  EXPECT_FALSE(absent.Open());
  EXPECT_NE(absent.error().find("No such file or directory"), std::string::npos) << absent.error();
  V4l2Options null_device;
  null_device.device = "/dev/null";
  V4l2Camera not_video(null_device, &io, &clock);
  EXPECT_FALSE(not_video.Open());
  EXPECT_NE(not_video.error().find("VIDIOC_QUERYCAP failed"), std::string::npos) << not_video.error();
}

// Hardware smoke test: CLOTHWIND_TEST_V4L2_DEVICE=/dev/video0 [CLOTHWIND_TEST_V4L2_FORMAT=MJPEG]
TEST(SyscallV4l2IoTest, CapturesFromARealCameraWhenAsked) {
  const char* device = std::getenv("CLOTHWIND_TEST_V4L2_DEVICE");
  if (device == nullptr || *device == '\0') GTEST_SKIP() << "CLOTHWIND_TEST_V4L2_DEVICE not set";
  V4l2Options o;
  o.device = device;
  if (const char* f = std::getenv("CLOTHWIND_TEST_V4L2_FORMAT")) {
    ASSERT_TRUE(ParsePixelFormat(f, &o.format, nullptr));
  }
  SyscallV4l2Io io;
  SystemClock clock;
  V4l2Camera camera(o, &io, &clock, [](LogLevel, const std::string& m) { std::printf("%s\n", m.c_str()); });
  ASSERT_TRUE(camera.Open()) << camera.error();
  int64_t previous = 0;
  int frames = 0;
  for (int i = 0; i < 200 && frames < 30; ++i) {
    Frame f;
    const ReadStatus s = camera.Read(&f, 0.5);
    if (s != ReadStatus::kFrame) continue;
    ++frames;
    EXPECT_GT(f.stamp_ns, previous);
    const double age = (clock.RosNs() - f.stamp_ns) * 1e-9;
    EXPECT_GT(age, 0.0);  // captured before it was read
    EXPECT_LT(age, 0.5);
    EXPECT_EQ(f.image.cols, camera.negotiated().width);
    previous = f.stamp_ns;
  }
  EXPECT_EQ(frames, 30) << camera.error();
  std::printf("%s: %s, drops %llu\n", device, DescribeNegotiated(camera.negotiated()).c_str(),
              static_cast<unsigned long long>(camera.stats().drops));
  camera.Close();
}

}  // namespace
}  // namespace sensors
}  // namespace clothwind
