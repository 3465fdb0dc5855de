#include "common/image_file.h"

#include <csetjmp>
#include <cstdio>  // jpeglib.h needs FILE
#include <string>

#include <jpeglib.h>

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
};

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
}

}  // namespace

std::string JpegDataProblem(const uint8_t* data, size_t n) {
  JpegErrors errors{};
  jpeg_decompress_struct info{};
  info.err = jpeg_std_error(&errors.pub);
  errors.pub.error_exit = JpegErrorExit;
  errors.pub.emit_message = JpegEmitMessage;
  if (setjmp(errors.jump)) {
    jpeg_destroy_decompress(&info);
    return errors.first;
  }
  jpeg_create_decompress(&info);
  jpeg_mem_src(&info, data, static_cast<unsigned long>(n));
  jpeg_read_header(&info, TRUE);
  if (static_cast<uint64_t>(info.image_width) * info.image_height > kMaxJpegPixels) {
    const std::string claim = "its header claims " + std::to_string(info.image_width) + "x" +
                              std::to_string(info.image_height) + " pixels (at most 2^30)";
    jpeg_destroy_decompress(&info);
    return claim;
  }
  jpeg_read_coefficients(&info);
  jpeg_finish_decompress(&info);
  jpeg_destroy_decompress(&info);
  return errors.warnings > 0 ? std::string(errors.first) : std::string();
}

std::string DecodeJpegBgr(const uint8_t* data, size_t n, cv::Mat* image) {
  JpegErrors errors{};
  jpeg_decompress_struct info{};
  info.err = jpeg_std_error(&errors.pub);
  errors.pub.error_exit = JpegErrorExit;
  errors.pub.emit_message = JpegEmitMessage;
  // (image lives in the caller's frame: what it holds after a longjmp is simply not used.)
  if (setjmp(errors.jump)) {
    jpeg_destroy_decompress(&info);
    return errors.first;
  }
  jpeg_create_decompress(&info);
  jpeg_mem_src(&info, data, static_cast<unsigned long>(n));
  jpeg_read_header(&info, TRUE);
  if (static_cast<uint64_t>(info.image_width) * info.image_height > kMaxJpegPixels) {
    const std::string claim = "its header claims " + std::to_string(info.image_width) + "x" +
                              std::to_string(info.image_height) + " pixels (at most 2^30)";
    jpeg_destroy_decompress(&info);
    return claim;
  }
  info.out_color_space = JCS_EXT_BGR;  // libjpeg-turbo's extension: OpenCV's channel order
  jpeg_start_decompress(&info);
  image->create(static_cast<int>(info.output_height), static_cast<int>(info.output_width), CV_8UC3);
  while (info.output_scanline < info.output_height) {
    JSAMPROW row = image->ptr<JSAMPLE>(static_cast<int>(info.output_scanline));
    jpeg_read_scanlines(&info, &row, 1);
  }
  jpeg_finish_decompress(&info);
  jpeg_destroy_decompress(&info);
  return errors.warnings > 0 ? std::string(errors.first) : std::string();
}

}  // namespace clothwind::common
