#include "sim/trajectory_io.h"

#include "common/atomic_file.h"
#include "common/regular_file.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <unistd.h>

namespace clothwind::sim {
namespace {

static_assert(sizeof(float) == 4 && sizeof(double) == 8, "IEEE 754 sizes expected");

bool LittleEndian() {
  const uint16_t one = 1;
  unsigned char b;
  std::memcpy(&b, &one, 1);
  return b == 1;
}

template <typename T>
void Put(std::string* out, T value) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  if (!LittleEndian()) std::reverse(bytes, bytes + sizeof(T));
  out->append(bytes, sizeof(T));
}

template <typename T>
T Get(const std::string& in, size_t* pos) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, in.data() + *pos, sizeof(T));
  if (!LittleEndian()) std::reverse(bytes, bytes + sizeof(T));
  *pos += sizeof(T);
  T value;
  std::memcpy(&value, bytes, sizeof(T));
  return value;
}

}  // namespace

void WriteFileAtomically(const std::string& path, const std::string& bytes) {
  clothwind::WriteFileAtomically(path, bytes);
}

void WriteTrajectory(const std::string& path, const Trajectory& t) {
  const size_t nv = t.uv.rows(), nf = t.faces.rows();
  for (size_t i = 0; i < t.frames.size(); ++i) {
    if (static_cast<size_t>(t.frames[i].rows()) != nv) {
      throw std::invalid_argument(path + ": frame " + std::to_string(i) + " has " +
                                  std::to_string(t.frames[i].rows()) + " vertices, uv has " +
                                  std::to_string(nv));
    }
  }
  std::string out;
  out.reserve(32 + 12 * nf + 8 * nv + 12 * nv * t.frames.size());
  out.append(kTrajectoryMagic, 8);
  Put<uint32_t>(&out, kTrajectoryVersion);
  Put<uint32_t>(&out, static_cast<uint32_t>(nv));
  Put<uint32_t>(&out, static_cast<uint32_t>(nf));
  Put<uint32_t>(&out, static_cast<uint32_t>(t.frames.size()));
  Put<double>(&out, t.frame_time);
  for (size_t f = 0; f < nf; ++f) {
    for (int c = 0; c < 3; ++c) Put<int32_t>(&out, t.faces(f, c));
  }
  for (size_t v = 0; v < nv; ++v) {
    Put<float>(&out, t.uv(v, 0));
    Put<float>(&out, t.uv(v, 1));
  }
  for (const auto& frame : t.frames) {
    for (size_t v = 0; v < nv; ++v) {
      for (int c = 0; c < 3; ++c) Put<float>(&out, frame(v, c));
    }
  }
  WriteFileAtomically(path, out);
}

Trajectory ReadTrajectory(const std::string& path) {
  // A folder opened as a stream read as empty ("truncated header (0 bytes, need 32)"), and a pipe
  // waited for a writer for ever.
  RefuseNonRegularFile(path, "a trajectory file (.cwtraj)");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot open trajectory");
  std::ostringstream ss;
  ss << in.rdbuf();
  const std::string data = ss.str();
  auto fail = [&](const std::string& what) { throw std::runtime_error(path + ": " + what); };
  if (data.size() < 32) fail("truncated header (" + std::to_string(data.size()) + " bytes, need 32)");
  if (std::memcmp(data.data(), kTrajectoryMagic, 8) != 0) fail("not a clothwind trajectory (bad magic)");
  size_t pos = 8;
  const uint32_t version = Get<uint32_t>(data, &pos);
  if (version != kTrajectoryVersion) {
    fail("unsupported version " + std::to_string(version) + " (expected " +
         std::to_string(kTrajectoryVersion) + ")");
  }
  const uint64_t nv = Get<uint32_t>(data, &pos), nf = Get<uint32_t>(data, &pos),
                 nframes = Get<uint32_t>(data, &pos);
  Trajectory t;
  t.frame_time = Get<double>(data, &pos);
  if (!(t.frame_time > 0) || !(t.frame_time <= 3600)) fail("frame_time must be in (0, 3600] s");
  // An empty trajectory crashed the renderer (bounds of no vertices); the size is checked in
  // pieces, each against what the file holds, so counts near 2^32 cannot wrap the sum.
  if (nv < 3 || nf < 1 || nframes < 1)
    fail("expected at least 3 vertices, 1 face and 1 frame, got " + std::to_string(nv) + ", " + std::to_string(nf) +
         ", " + std::to_string(nframes));
  const uint64_t payload = data.size() - 32;
  if (12 * nf > payload || 8 * nv > payload - 12 * nf || nframes > (payload - 12 * nf - 8 * nv) / (12 * nv))
    fail("size " + std::to_string(data.size()) + " bytes is less than its header (#V " + std::to_string(nv) +
         ", #F " + std::to_string(nf) + ", #frames " + std::to_string(nframes) + ") implies");
  const uint64_t expected = 32 + 12 * nf + 8 * nv + 12 * nv * nframes;
  if (data.size() != expected) {
    fail("size " + std::to_string(data.size()) + " bytes, header (#V " + std::to_string(nv) +
         ", #F " + std::to_string(nf) + ", #frames " + std::to_string(nframes) + ") implies " +
         std::to_string(expected));
  }
  t.faces.resize(nf, 3);
  for (uint64_t f = 0; f < nf; ++f) {
    for (int c = 0; c < 3; ++c) {
      const int32_t idx = Get<int32_t>(data, &pos);
      if (idx < 0 || static_cast<uint64_t>(idx) >= nv) {
        fail("face " + std::to_string(f) + " index " + std::to_string(idx) + " out of range");
      }
      t.faces(f, c) = idx;
    }
  }
  t.uv.resize(nv, 2);
  for (uint64_t v = 0; v < nv; ++v) {
    t.uv(v, 0) = Get<float>(data, &pos);
    t.uv(v, 1) = Get<float>(data, &pos);
    if (!std::isfinite(t.uv(v, 0)) || !std::isfinite(t.uv(v, 1)))
      fail("vertex " + std::to_string(v) + "'s texture coordinates are not finite");
  }
  t.frames.resize(nframes);
  for (uint64_t k = 0; k < nframes; ++k) {
    t.frames[k].resize(nv, 3);
    for (uint64_t v = 0; v < nv; ++v) {
      for (int c = 0; c < 3; ++c) {
        const float x = Get<float>(data, &pos);
        if (!std::isfinite(x)) fail("frame " + std::to_string(k) + " vertex " + std::to_string(v) + " is not finite");
        t.frames[k](v, c) = x;
      }
    }
  }
  return t;
}

}  // namespace clothwind::sim
