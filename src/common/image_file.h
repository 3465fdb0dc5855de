// Reading an image file whole or not at all. Why: libjpeg decodes a JPEG cut short (a copy
// interrupted, a recording cut by a power loss, a USB transfer lost) with grey rows where the
// data ends and only prints a warning, so cv::imread hands back an image that is partly made up;
// a dataset reader or a replay that takes it trains on, or publishes, the made-up part. A JPEG
// must therefore carry its start- and end-of-image markers, and its entropy-coded data must decode
// without a libjpeg warning (a file damaged in its middle keeps both markers and decodes into
// made-up blocks, with only "Corrupt JPEG data" on stderr, naming no file). The check costs about
// half a grey decode again (libjpeg entropy-decodes every colour component). OpenCV's imgcodecs,
// and libjpeg in image_file.cc.
#ifndef CLOTHWIND_COMMON_IMAGE_FILE_H_
#define CLOTHWIND_COMMON_IMAGE_FILE_H_

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

namespace clothwind::common {

// Whether `data` (n bytes) starts like a JPEG (the start-of-image marker FF D8).
inline bool LooksLikeJpeg(const uint8_t* data, size_t n) {
  return n >= 2 && data[0] == 0xFF && data[1] == 0xD8;
}

// Checks that a JPEG's bytes are whole: the start-of-image marker first, then its segments in
// turn, each skipped by its length (an embedded thumbnail lies inside its APP1 segment), every
// scan's entropy-coded data up to the next marker (inside it an FF byte is followed by 00, a
// restart marker or more FF fill), until the end-of-image marker (FF D9) after at least one scan.
// Anything may follow the end (cameras pad their buffers with zeros; phones append trailers,
// a Motion Photo a whole MP4, whose bytes may hold FF DA: searching the file for the last FF DA
// took such a trailer for the last scan and refused the photo as truncated). Bytes that are not
// a marker where one is due are skipped to the next FF, as libjpeg does (it warns of
// "extraneous bytes", which JpegDataProblem judges), and so is a segment whose length runs past
// the end (damage; a cut shows as no end after the last scan).
// Inputs: data, n  the encoded bytes. Output: "" when whole, else why not (for an error message).
inline std::string JpegWholeness(const uint8_t* data, size_t n) {
  if (n < 4 || !LooksLikeJpeg(data, n)) return "no start-of-image marker (" + std::to_string(n) + " bytes)";
  const auto standalone = [](uint8_t m) { return m == 0x01 || m == 0xD8 || (m >= 0xD0 && m <= 0xD7); };
  bool scanned = false;
  size_t i = 2;
  while (true) {
    while (i < n && data[i] != 0xFF) ++i;                // extraneous bytes
    while (i + 1 < n && data[i + 1] == 0xFF) ++i;        // fill bytes before the marker
    if (i + 1 >= n) break;
    const uint8_t marker = data[i + 1];
    i += 2;
    if (marker == 0xD9) {
      if (scanned) return "";
      continue;  // an end before any scan is no image's end: what follows decides
    }
    if (marker == 0x00 || standalone(marker)) continue;
    // A length past the end or below its own two bytes is damage (an FF byte overwritten in the
    // data reads as a marker), not a cut: the search goes on from the marker, as before segments
    // were walked, and JpegDataProblem says what libjpeg makes of it.
    const size_t length = i + 2 <= n ? (static_cast<size_t>(data[i]) << 8) | data[i + 1] : 0;
    scanned = scanned || marker == 0xDA;
    if (length < 2 || length > n - i) continue;
    i += length;
    if (marker != 0xDA) continue;
    // Entropy-coded data: up to an FF that starts a marker other than a restart.
    while (i + 1 < n && !(data[i] == 0xFF && data[i + 1] != 0x00 && data[i + 1] != 0xFF &&
                          !(data[i + 1] >= 0xD0 && data[i + 1] <= 0xD7)))
      ++i;
  }
  const std::string size = " (" + std::to_string(n) + " bytes)";
  if (!scanned) return "no image data: no start-of-scan marker" + size;
  return "truncated: no end-of-image marker after its last scan" + size;
}

// Entropy-decodes a JPEG's data (its DCT coefficients; no inverse DCT, no colour conversion) and
// reports libjpeg's error, or its first warning that the image data is damaged
// (common/image_file.cc; the warnings DecodeJpegBgr refuses: up to 16 extraneous bytes before a
// marker, a camera's padding, and an unknown JFIF revision leave the picture whole). An image that claims
// more than kMaxJpegPixels is refused from its header, before libjpeg sets aside its coefficients
// (a 1 kB file claiming 40000x40000 took 3 GB; OpenCV refuses such a file at once).
// Inputs: data, n  the encoded bytes (a JPEG: LooksLikeJpeg).
// Output: "" when the data decoded cleanly, else libjpeg's message, e.g.
//   "Corrupt JPEG data: 99 extraneous bytes before marker 0xd9".
constexpr uint64_t kMaxJpegPixels = uint64_t{1} << 30;  // OpenCV's CV_IO_MAX_IMAGE_PIXELS
std::string JpegDataProblem(const uint8_t* data, size_t n);

// Decodes a JPEG into 8-bit BGR in one pass of libjpeg, keeping its warnings that the image data
// is damaged: a frame damaged inside intact markers (a USB camera's MJPEG with a corrupted
// transfer) decodes into made-up blocks with only a warning, which cv::imdecode drops. Warnings
// that leave the picture whole are not refused (up to 16 "extraneous bytes before marker", the
// padding some cameras such as the Logitech C270 send on every MJPEG frame; an unknown JFIF
// revision). libjpeg notices only part of the damage: a frame it decodes without a word can still
// be partly made up (18 of 40 ten-byte damages in the test). Same cost as cv::imdecode
// (both are libjpeg-turbo; JpegDataProblem first would add half a decode per frame). Grey JPEGs
// come out as BGR too; CMYK ones are refused (no camera sends them). Refuses an image claiming
// more than kMaxJpegPixels, or another size than expected, from its header.
// Inputs: data, n  the encoded bytes; expected_width, expected_height  the size the image must
//   have (0: any).
// Outputs: *image (rows x cols, CV_8UC3) on success. Returns "" when it decoded with its data
//   whole, else libjpeg's error or first damage warning, e.g. "Corrupt JPEG data: bad Huffman
//   code", or the size mismatch (*image is then not to be used).
std::string DecodeJpegBgr(const uint8_t* data, size_t n, cv::Mat* image, int expected_width = 0,
                          int expected_height = 0);

// Reads and decodes an image file as cv::imread(path, flags) does, refusing a JPEG that is not
// whole (JpegWholeness) or whose data libjpeg finds corrupt (JpegDataProblem), and catching OpenCV's exceptions (a header claiming more pixels than it
// allows throws).
// Inputs: path  the file; flags  cv::IMREAD_* as for cv::imread.
// Outputs: the image, or an empty cv::Mat with *error (when not null) saying why: "cannot read",
//   "JPEG truncated: ...", "JPEG data corrupt: ...", "not a readable image".
inline cv::Mat ReadImageFile(const std::filesystem::path& path, int flags, std::string* error) {
  auto fail = [&](const std::string& why) {
    if (error) *error = why;
    return cv::Mat();
  };
  // A folder opens as a stream and then threw "basic_filebuf::underflow ... Is a directory".
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) return fail("is a folder, not an image");
  std::ifstream in(path, std::ios::binary);
  if (!in) return fail("cannot read");
  const std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) return fail("cannot read");
  if (bytes.empty()) return fail("not a readable image (empty file)");
  if (LooksLikeJpeg(bytes.data(), bytes.size())) {
    const std::string why = JpegWholeness(bytes.data(), bytes.size());
    if (!why.empty()) return fail("JPEG " + why);
    const std::string corrupt = JpegDataProblem(bytes.data(), bytes.size());
    if (!corrupt.empty()) return fail("JPEG data corrupt: " + corrupt);
  }
  cv::Mat image;
  try {
    image = cv::imdecode(bytes, flags);
  } catch (const cv::Exception& e) {
    return fail("not a readable image (" + e.err + ")");
  }
  if (image.empty()) return fail("not a readable image");
  return image;
}

}  // namespace clothwind::common

#endif  // CLOTHWIND_COMMON_IMAGE_FILE_H_
