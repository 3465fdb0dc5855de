// Reading an image file whole or not at all. Why: libjpeg decodes a JPEG cut short (a copy
// interrupted, a recording cut by a power loss, a USB transfer lost) with grey rows where the
// data ends and only prints a warning, so cv::imread hands back an image that is partly made up;
// a dataset reader or a replay that takes it trains on, or publishes, the made-up part. A JPEG
// must therefore carry its start- and end-of-image markers, and its entropy-coded data must decode
// without a libjpeg warning (a file damaged in its middle keeps both markers and decodes into
// made-up blocks, with only "Corrupt JPEG data" on stderr, naming no file). Header-only
// (OpenCV's imgcodecs and libjpeg, which the clothwind_common target links).
#ifndef CLOTHWIND_COMMON_IMAGE_FILE_H_
#define CLOTHWIND_COMMON_IMAGE_FILE_H_

#include <csetjmp>
#include <cstddef>
#include <cstdint>
#include <cstdio>  // jpeglib.h needs FILE
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <jpeglib.h>

namespace clothwind::common {

// Whether `data` (n bytes) starts like a JPEG (the start-of-image marker FF D8).
inline bool LooksLikeJpeg(const uint8_t* data, size_t n) {
  return n >= 2 && data[0] == 0xFF && data[1] == 0xD8;
}

// Checks that a JPEG's bytes are whole: the start-of-image marker first, and the end-of-image
// marker (FF D9) after the start of its last scan (FF DA). Inside a scan's entropy-coded data an
// FF byte is always followed by 00 or a restart marker, so neither marker appears there; an
// embedded thumbnail's scan and end come before the main image's scan. Anything may follow the
// end (cameras pad their buffers with zeros; phones append trailers).
// Inputs: data, n  the encoded bytes. Output: "" when whole, else why not (for an error message).
inline std::string JpegWholeness(const uint8_t* data, size_t n) {
  if (n < 4 || !LooksLikeJpeg(data, n)) return "no start-of-image marker (" + std::to_string(n) + " bytes)";
  size_t last_scan = 0;
  for (size_t i = 2; i + 1 < n; ++i)
    if (data[i] == 0xFF && data[i + 1] == 0xDA) last_scan = i;
  if (last_scan == 0) return "no image data: no start-of-scan marker (" + std::to_string(n) + " bytes)";
  for (size_t i = last_scan + 2; i + 1 < n; ++i)
    if (data[i] == 0xFF && data[i + 1] == 0xD9) return "";
  return "truncated: no end-of-image marker after its last scan (" + std::to_string(n) + " bytes)";
}

namespace internal {

// libjpeg's error manager, with the first message kept and errors turned into a longjmp (its
// default error_exit calls exit()). Plain data: longjmp skips no destructor.
struct JpegErrors {
  jpeg_error_mgr pub;  // first: libjpeg hands back &pub as the j_common_ptr's err
  std::jmp_buf jump;
  int warnings;
  char first[JMSG_LENGTH_MAX];
};

inline void JpegErrorExit(j_common_ptr c) {
  auto* e = reinterpret_cast<JpegErrors*>(c->err);
  (*c->err->format_message)(c, e->first);
  std::longjmp(e->jump, 1);
}

// level < 0: a warning (corrupt data); >= 0: trace messages, ignored as libjpeg's default does.
inline void JpegEmitMessage(j_common_ptr c, int level) {
  if (level >= 0) return;
  auto* e = reinterpret_cast<JpegErrors*>(c->err);
  if (e->warnings++ == 0) (*c->err->format_message)(c, e->first);
}

}  // namespace internal

// Entropy-decodes a JPEG's data (its DCT coefficients; no inverse DCT, no colour conversion,
// about a third of a full decode) and reports the first warning or error libjpeg raised.
// Inputs: data, n  the encoded bytes (a JPEG: LooksLikeJpeg).
// Output: "" when the data decoded cleanly, else libjpeg's message, e.g.
//   "Corrupt JPEG data: 99 extraneous bytes before marker 0xd9".
inline std::string JpegDataProblem(const uint8_t* data, size_t n) {
  internal::JpegErrors errors{};
  jpeg_decompress_struct info{};
  info.err = jpeg_std_error(&errors.pub);
  errors.pub.error_exit = internal::JpegErrorExit;
  errors.pub.emit_message = internal::JpegEmitMessage;
  if (setjmp(errors.jump)) {
    jpeg_destroy_decompress(&info);
    return errors.first;
  }
  jpeg_create_decompress(&info);
  jpeg_mem_src(&info, data, static_cast<unsigned long>(n));
  jpeg_read_header(&info, TRUE);
  jpeg_read_coefficients(&info);
  jpeg_finish_decompress(&info);
  jpeg_destroy_decompress(&info);
  return errors.warnings > 0 ? std::string(errors.first) : std::string();
}

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
