#include "common/image_file.h"

#include <csetjmp>
#include <cstdio>  // jpeglib.h needs FILE
#include <string>

#include <jpeglib.h>
#include <jerror.h>  // the JWRN_ message codes

namespace clothwind::common {
namespace {

// libjpeg's error manager, with the first message kept and errors turned into a longjmp (its
// default error_exit calls exit()). Plain data: the longjmp crosses only libjpeg's C frames and
// JpegDataProblem's, which hold nothing with a destructor when it is taken.
struct JpegErrors {
  jpeg_error_mgr pub;  // first: libjpeg hands back &pub as the j_common_ptr's err
  std::jmp_buf jump;
  int warnings;
  char first[JMSG_LENGTH_MAX];
  int damage_warnings;  // warnings that the entropy-coded data is damaged (IsDataDamage)
  char first_damage[JMSG_LENGTH_MAX];
};

// More bytes than this left before a marker mean the decoder lost its place in damaged data (ten
// bytes overwritten in a 128x96 frame left 79 before the end marker, the picture made up); a
// camera's padding is a byte or a few (the Logitech C270 leaves some before restart markers on
// every MJPEG frame, whose picture is whole).
constexpr int kMaxPaddingBytes = 16;

// Whether libjpeg's warning (code, its parameters) says the image data itself is damaged, so the
// decoded picture is partly made up. Others leave the picture whole: a few padding bytes before a
// marker, an unknown JFIF revision, a bad ICC marker.
bool IsDataDamage(const jpeg_error_mgr& err) {
  const int code = err.msg_code;
  if (code == JWRN_EXTRANEOUS_DATA) return err.msg_parm.i[0] > kMaxPaddingBytes;
  return code == JWRN_HUFF_BAD_CODE || code == JWRN_ARITH_BAD_CODE || code == JWRN_HIT_MARKER ||
         code == JWRN_JPEG_EOF || code == JWRN_MUST_RESYNC || code == JWRN_NOT_SEQUENTIAL;
}

void JpegErrorExit(j_common_ptr c) {
  auto* e = reinterpret_cast<JpegErrors*>(c->err);
  (*c->err->format_message)(c, e->first);
  std::longjmp(e->jump, 1);
}

// level < 0: a warning (corrupt data); >= 0: trace messages, ignored as libjpeg's default does.
void JpegEmitMessage(j_common_ptr c, int level) {
  if (level >= 0) return;
  auto* e = reinterpret_cast<JpegErrors*>(c->err);
  if (e->warnings++ == 0) (*c->err->format_message)(c, e->first);
  if (IsDataDamage(*c->err) && e->damage_warnings++ == 0) (*c->err->format_message)(c, e->first_damage);
}

// Hands libjpeg errors to JpegErrorExit (a longjmp to errors->jump, set by the caller: the
// frame that calls setjmp must be the one libjpeg is called from) and warnings to JpegEmitMessage.
void UseErrors(JpegErrors* errors, jpeg_decompress_struct* info) {
  info->err = jpeg_std_error(&errors->pub);
  errors->pub.error_exit = JpegErrorExit;
  errors->pub.emit_message = JpegEmitMessage;
}

// "" when the header read into `info` claims at most kMaxJpegPixels, else why it is refused.
std::string ClaimTooLarge(const jpeg_decompress_struct& info) {
  if (static_cast<uint64_t>(info.image_width) * info.image_height <= kMaxJpegPixels) return "";
  return "its header claims " + std::to_string(info.image_width) + "x" + std::to_string(info.image_height) +
         " pixels (at most 2^30)";
}

// Creates the decompressor on `data` and reads its header; "" or why the header is refused
// (ClaimTooLarge). libjpeg's errors longjmp to the caller's setjmp, so it is called only after it.
std::string StartDecompress(jpeg_decompress_struct* info, const uint8_t* data, size_t n) {
  jpeg_create_decompress(info);
  jpeg_mem_src(info, data, static_cast<unsigned long>(n));
  jpeg_read_header(info, TRUE);
  return ClaimTooLarge(*info);
}

}  // namespace

std::string JpegDataProblem(const uint8_t* data, size_t n) {
  JpegErrors errors{};
  jpeg_decompress_struct info{};
  UseErrors(&errors, &info);
  if (setjmp(errors.jump)) {
    jpeg_destroy_decompress(&info);
    return errors.first;
  }
  if (const std::string claim = StartDecompress(&info, data, n); !claim.empty()) {
    jpeg_destroy_decompress(&info);
    return claim;
  }
  jpeg_read_coefficients(&info);
  jpeg_finish_decompress(&info);
  jpeg_destroy_decompress(&info);
  // Only warnings of damage, as DecodeJpegBgr: a Logitech C270's MJPEG frame saved to a folder
  // (its few padding bytes before restart markers) was refused frame by frame on replay, while the
  // live camera published the same frames.
  return errors.damage_warnings > 0 ? std::string(errors.first_damage) : std::string();
}

std::string DecodeJpegBgr(const uint8_t* data, size_t n, cv::Mat* image, int expected_width,
                          int expected_height) {
  JpegErrors errors{};
  jpeg_decompress_struct info{};
  UseErrors(&errors, &info);
  // (image lives in the caller's frame: what it holds after a longjmp is simply not used.)
  if (setjmp(errors.jump)) {
    jpeg_destroy_decompress(&info);
    return errors.first;
  }
  if (const std::string claim = StartDecompress(&info, data, n); !claim.empty()) {
    jpeg_destroy_decompress(&info);
    return claim;
  }
  if (expected_width > 0 && (static_cast<int64_t>(info.image_width) != expected_width ||
                             static_cast<int64_t>(info.image_height) != expected_height)) {
    // Before any memory is set aside: a damaged header can claim gigabytes.
    const std::string size = "decodes to " + std::to_string(info.image_width) + "x" +
                             std::to_string(info.image_height) + ", expected " + std::to_string(expected_width) +
                             "x" + std::to_string(expected_height);
    jpeg_destroy_decompress(&info);
    return size;
  }
  info.out_color_space = JCS_EXT_BGR;  // libjpeg-turbo's extension: OpenCV's channel order
  jpeg_start_decompress(&info);
  try {
    image->create(static_cast<int>(info.output_height), static_cast<int>(info.output_width), CV_8UC3);
  } catch (const std::exception& e) {
    jpeg_destroy_decompress(&info);
    return std::string("cannot allocate the image: ") + e.what();
  }
  while (info.output_scanline < info.output_height) {
    JSAMPROW row = image->ptr<JSAMPLE>(static_cast<int>(info.output_scanline));
    jpeg_read_scanlines(&info, &row, 1);
  }
  jpeg_finish_decompress(&info);
  jpeg_destroy_decompress(&info);
  return errors.damage_warnings > 0 ? std::string(errors.first_damage) : std::string();
}

}  // namespace clothwind::common
