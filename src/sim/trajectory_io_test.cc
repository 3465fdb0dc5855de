#include "sim/trajectory_io.h"

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

#include <gtest/gtest.h>
#include <unistd.h>

namespace clothwind::sim {
namespace {

namespace fs = std::filesystem;

Trajectory Sample() {
  Trajectory t;
  t.faces.resize(2, 3);
  t.faces << 0, 1, 2, 0, 2, 3;
  t.uv.resize(4, 2);
  t.uv << 0, 0, 1, 0, 1, 1, 0, 1;
  t.frame_time = 0.04;
  for (int k = 0; k < 3; ++k) {
    FramePositions p(4, 3);
    for (int v = 0; v < 4; ++v) p.row(v) << 0.1f * k, t.uv(v, 0), t.uv(v, 1) - 0.01f * k * v;
    t.frames.push_back(p);
  }
  return t;
}

std::string TempPath(const std::string& name) {
  return (fs::temp_directory_path() / ("cwtraj_" + std::to_string(::getpid()) + "_" + name)).string();
}

TEST(TrajectoryIo, RoundTripIsExactAndSizeMatchesTheDocumentedLayout) {
  const Trajectory t = Sample();
  const std::string path = TempPath("ok.cwtraj");
  WriteTrajectory(path, t);
  EXPECT_EQ(fs::file_size(path), 32u + 12 * 2 + 8 * 4 + 12 * 4 * 3);
  // Header bytes as documented.
  std::ifstream in(path, std::ios::binary);
  char header[32];
  in.read(header, 32);
  EXPECT_EQ(std::string(header, 6), "CWTRAJ");
  EXPECT_EQ(header[8], 1);   // version, little-endian
  EXPECT_EQ(header[12], 4);  // #V
  EXPECT_EQ(header[16], 2);  // #F
  EXPECT_EQ(header[20], 3);  // #frames
  in.close();
  // The body at the documented offsets (docs/scenes.md, trajectory_io.h): a round trip alone
  // passes any layout the writer and reader agree on (1-based faces, uv after the frames, ...).
  std::string bytes;
  {
    std::ifstream whole(path, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(whole), std::istreambuf_iterator<char>());
  }
  ASSERT_EQ(bytes.size(), 32u + 12 * 2 + 8 * 4 + 12 * 4 * 3);
  auto at = [&bytes](auto value, size_t offset) {  // the little-endian value at offset
    static_assert(sizeof(value) == 4 || sizeof(value) == 8);
    unsigned char b[8];
    for (size_t i = 0; i < sizeof(value); ++i) b[i] = static_cast<unsigned char>(bytes[offset + i]);
    uint64_t u = 0;
    for (size_t i = sizeof(value); i-- > 0;) u = (u << 8) | b[i];
    if constexpr (sizeof(value) == 4) {
      const uint32_t u32 = static_cast<uint32_t>(u);
      std::memcpy(&value, &u32, 4);
    } else {
      std::memcpy(&value, &u, 8);
    }
    return value;
  };
  EXPECT_EQ(bytes.substr(0, 8), std::string("CWTRAJ\0\0", 8));
  EXPECT_EQ(at(uint32_t{}, 8), 1u);
  EXPECT_EQ(at(uint32_t{}, 12), 4u);
  EXPECT_EQ(at(uint32_t{}, 16), 2u);
  EXPECT_EQ(at(uint32_t{}, 20), 3u);
  EXPECT_EQ(at(double{}, 24), 0.04);
  const size_t faces_at = 32, uv_at = faces_at + 12 * 2, frames_at = uv_at + 8 * 4;
  for (int f = 0; f < 2; ++f)
    for (int c = 0; c < 3; ++c)
      EXPECT_EQ(at(int32_t{}, faces_at + 12 * f + 4 * c), t.faces(f, c)) << "face " << f << " corner " << c;
  for (int v = 0; v < 4; ++v)
    for (int c = 0; c < 2; ++c) EXPECT_EQ(at(float{}, uv_at + 8 * v + 4 * c), t.uv(v, c)) << "uv " << v;
  for (int k = 0; k < 3; ++k)
    for (int v = 0; v < 4; ++v)
      for (int c = 0; c < 3; ++c)
        EXPECT_EQ(at(float{}, frames_at + 48 * k + 12 * v + 4 * c), t.frames[k](v, c))
            << "frame " << k << " vertex " << v << " coordinate " << c;
  EXPECT_EQ(at(float{}, frames_at + 48 * 1), 0.1f);  // frame 1, vertex 0, x (spelled out)
  const Trajectory r = ReadTrajectory(path);
  EXPECT_EQ(r.faces, t.faces);
  EXPECT_EQ(r.uv, t.uv);
  EXPECT_DOUBLE_EQ(r.frame_time, t.frame_time);
  ASSERT_EQ(r.num_frames(), 3);
  for (int k = 0; k < 3; ++k) EXPECT_EQ(r.frames[k], t.frames[k]);
  // No temporary file left behind.
  int files = 0;
  for (const auto& e : fs::directory_iterator(fs::temp_directory_path())) {
    if (e.path().string().rfind(path, 0) == 0) ++files;
  }
  EXPECT_EQ(files, 1);
  fs::remove(path);
}

TEST(TrajectoryIo, CorruptFilesFailNamingTheFileAndProblem) {
  const std::string path = TempPath("bad.cwtraj");
  WriteTrajectory(path, Sample());
  fs::resize_file(path, fs::file_size(path) - 4);
  try {
    ReadTrajectory(path);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("implies"), std::string::npos) << e.what();
  }
  std::ofstream(path, std::ios::binary) << "NOTATRAJECTORY_AT_ALL_PADDING_PADDING_PADDING";
  EXPECT_THROW(ReadTrajectory(path), std::runtime_error);
  fs::remove(path);
  EXPECT_THROW(ReadTrajectory(path), std::runtime_error);
  Trajectory t = Sample();
  t.frames[1].resize(3, 3);
  EXPECT_THROW(WriteTrajectory(path, t), std::invalid_argument);

  // Headers that lie: no vertices (the renderer crashed on it), counts whose byte total wraps
  // 64 bits (it passed the size check and read past the file), a frame time of 1e300.
  auto header = [&](uint32_t nv, uint32_t nf, uint32_t nframes, double frame_time) {
    std::string h(kTrajectoryMagic, 8);
    auto put = [&h](const void* p, size_t n) { h.append(static_cast<const char*>(p), n); };
    const uint32_t version = kTrajectoryVersion;
    put(&version, 4);
    put(&nv, 4);
    put(&nf, 4);
    put(&nframes, 4);
    put(&frame_time, 8);
    std::ofstream(path, std::ios::binary) << h;
  };
  auto expect = [&](const std::string& what) {
    try {
      ReadTrajectory(path);
      ADD_FAILURE() << "accepted: " << what;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  header(0, 0, 1, 0.04);
  expect("expected at least 3 vertices, 1 face and 1 frame");
  header(2147483648u, 1, 715827882u, 0.04);
  expect("is less than its header");
  header(3, 1, 1, 1e300);
  expect("frame_time must be in (0, 3600] s");
}

}  // namespace
}  // namespace clothwind::sim
