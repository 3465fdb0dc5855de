#include "learn/zip_checksums.h"

#include <zlib.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>

namespace clothwind::learn {
namespace {

// Little-endian fields, as the ZIP format stores them (APPNOTE.TXT).
uint64_t Le(const std::string& b, size_t at, int bytes) {
  uint64_t v = 0;
  for (int i = bytes - 1; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(b[at + i]);
  return v;
}

constexpr uint32_t kEndOfDirectory = 0x06054b50, kZip64End = 0x06064b50, kZip64Locator = 0x07064b50,
                   kDirectoryEntry = 0x02014b50, kLocalHeader = 0x04034b50;

}  // namespace

void VerifyZipChecksums(const std::filesystem::path& path) {
  const std::string where = path.string() + ": ";
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(where + "cannot open");
  const std::string b((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  auto fail = [&](const std::string& why) { throw std::runtime_error(where + why); };
  auto need = [&](uint64_t at, uint64_t size, const char* what) {
    if (at > b.size() || size > b.size() - at) fail(std::string("cut short (") + what + " beyond its end)");
  };
  // The end-of-directory record: 22 bytes plus a comment of up to 65535, at the very end.
  if (b.size() < 22) fail("not a ZIP archive (" + std::to_string(b.size()) + " bytes)");
  size_t end = std::string::npos;
  for (size_t at = b.size() - 22;; --at) {
    if (Le(b, at, 4) == kEndOfDirectory && at + 22 + Le(b, at + 20, 2) == b.size()) {
      end = at;
      break;
    }
    if (at == 0 || b.size() - at > 22 + 65535) break;
  }
  if (end == std::string::npos) fail("not a ZIP archive (no end-of-directory record)");
  uint64_t entries = Le(b, end + 10, 2), directory = Le(b, end + 16, 4);
  if (entries == 0xFFFF || directory == 0xFFFFFFFF) {  // ZIP64: the real figures are in its record
    if (end < 20 || Le(b, end - 20, 4) != kZip64Locator) fail("cut short (no ZIP64 end-of-directory locator)");
    const uint64_t record = Le(b, end - 20 + 8, 8);
    need(record, 56, "the ZIP64 end-of-directory record");
    if (Le(b, record, 4) != kZip64End) fail("damaged (no ZIP64 end-of-directory record where its locator points)");
    entries = Le(b, record + 32, 8);
    directory = Le(b, record + 48, 8);
  }
  uint64_t at = directory;
  for (uint64_t e = 0; e < entries; ++e) {
    need(at, 46, "the central directory");
    if (Le(b, at, 4) != kDirectoryEntry) fail("damaged (central directory entry " + std::to_string(e) + ")");
    const uint64_t method = Le(b, at + 10, 2), crc = Le(b, at + 16, 4);
    uint64_t size = Le(b, at + 20, 4), original = Le(b, at + 24, 4), local = Le(b, at + 42, 4);
    const uint64_t name_length = Le(b, at + 28, 2), extra_length = Le(b, at + 30, 2), comment = Le(b, at + 32, 2);
    need(at + 46, name_length + extra_length + comment, "the central directory");
    const std::string name = b.substr(at + 46, name_length);
    // ZIP64 extra field (id 1): the 8-byte figures of those the entry gives as 0xFFFFFFFF, in order.
    for (uint64_t x = at + 46 + name_length; x + 4 <= at + 46 + name_length + extra_length;) {
      const uint64_t id = Le(b, x, 2), length = Le(b, x + 2, 2);
      if (id == 1) {
        uint64_t f = x + 4;
        for (uint64_t* field : {&original, &size, &local})
          if (*field == 0xFFFFFFFF && f + 8 <= x + 4 + length) {
            *field = Le(b, f, 8);
            f += 8;
          }
      }
      x += 4 + length;
    }
    need(local, 30, ("the local header of entry " + name).c_str());
    if (Le(b, local, 4) != kLocalHeader) fail("damaged (no local header for entry " + name + ")");
    const uint64_t data = local + 30 + Le(b, local + 26, 2) + Le(b, local + 28, 2);
    need(data, size, ("entry " + name).c_str());
    if (method == 0) {
      uLong sum = crc32(0L, Z_NULL, 0);
      for (uint64_t done = 0; done < size;) {  // in pieces: crc32 takes a uInt length
        const uInt piece = static_cast<uInt>(std::min<uint64_t>(size - done, 1u << 30));
        sum = crc32(sum, reinterpret_cast<const Bytef*>(b.data() + data + done), piece);
        done += piece;
      }
      if (sum != crc) {
        char why[96];
        std::snprintf(why, sizeof(why), " fails its checksum (CRC-32 %08llx, the archive's directory says %08llx)",
                      static_cast<unsigned long long>(sum), static_cast<unsigned long long>(crc));
        fail("entry " + name + why + ": the file is damaged (copy it again from where it was made)");
      }
    }
    at += 46 + name_length + extra_length + comment;
  }
}

}  // namespace clothwind::learn
