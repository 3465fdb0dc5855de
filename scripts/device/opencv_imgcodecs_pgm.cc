// A stand-in for OpenCV's imgcodecs on a lent GPU machine (scripts/device-train), built into a
// library with imgcodecs' file name. Debian's imgcodecs needs GDAL, OpenEXR, GDCM and ~140
// libraries in all (181 MB), far over what may travel to that machine (64 MiB), while a FlagSim
// made with `make-dataset --format pgm` needs only binary PGM. So this reads and writes binary
// PGM (P5, 8-bit) and refuses every other format with an error naming the file; nothing else of
// clothwind runs there.
//
// The functions are those clothwind's libraries call (nm -D --undefined-only), and those Debian's
// libtorch loads through its own OpenCV (for `--check` here), declared by OpenCV's own header so
// their symbols match. Not part of the product: it never builds in CI
// except through `scripts/device-train --check`.
#include <cctype>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace cv {
namespace {

bool IsPgm(const std::string& filename) {
  const size_t dot = filename.rfind('.');
  return dot != std::string::npos && filename.substr(dot) == ".pgm";
}

[[noreturn]] void Refuse(const std::string& what) {
  throw std::runtime_error(what + ": this machine's stand-in for OpenCV's imgcodecs reads and writes "
                           "binary PGM only (make the dataset with --format pgm)");
}

// The next header token of a PGM stream, skipping white space and '#' comments.
std::string Token(std::istream& in) {
  std::string token;
  while (in) {
    const int c = in.get();
    if (c == '#') {
      std::string comment;
      std::getline(in, comment);
    } else if (std::isspace(c) || c == EOF) {
      if (!token.empty()) return token;
    } else {
      token.push_back(static_cast<char>(c));
    }
  }
  return token;
}

// Decodes a binary PGM stream (P5, maxval <= 255): one channel, or three equal ones with
// IMREAD_COLOR as the real decoder gives them. Empty Mat when it is not one, as imread.
Mat DecodePgm(std::istream& in, int flags) {
  if (Token(in) != "P5") return Mat();
  int width = 0, height = 0, maxval = 0;
  try {
    width = std::stoi(Token(in));
    height = std::stoi(Token(in));
    maxval = std::stoi(Token(in));
  } catch (const std::exception&) {
    return Mat();
  }
  if (width <= 0 || height <= 0 || maxval <= 0 || maxval > 255) return Mat();
  Mat grey(height, width, CV_8UC1);
  in.read(reinterpret_cast<char*>(grey.data), static_cast<std::streamsize>(grey.total()));
  if (in.gcount() != static_cast<std::streamsize>(grey.total())) return Mat();
  if (flags == IMREAD_COLOR) {
    Mat colour;
    cvtColor(grey, colour, COLOR_GRAY2BGR);
    return colour;
  }
  return grey;
}

}  // namespace

Mat imread(const String& filename, int flags) {
  if (!IsPgm(filename)) Refuse("imread " + filename);
  std::ifstream in(filename, std::ios::binary);
  if (!in) return Mat();
  return DecodePgm(in, flags);
}

// Decodes PGM bytes (clothwind reads its frames whole, then decodes: common/image_file.h).
Mat imdecode(InputArray buf, int flags) {
  const Mat bytes = buf.getMat();
  const std::string data(reinterpret_cast<const char*>(bytes.data), bytes.total() * bytes.elemSize());
  if (data.size() < 2 || data[0] != 'P' || data[1] != '5') Refuse("imdecode of a buffer that is not a binary PGM");
  std::istringstream in(data);
  return DecodePgm(in, flags);
}
Mat imdecode(InputArray buf, int flags, Mat* dst) {
  Mat m = imdecode(buf, flags);
  if (dst) *dst = m;
  return m;
}

// Writes an 8-bit single-channel image as binary PGM.
bool imwrite(const String& filename, InputArray img, const std::vector<int>& /*params*/) {
  if (!IsPgm(filename)) Refuse("imwrite " + filename);
  const Mat m = img.getMat();
  if (m.type() != CV_8UC1) Refuse("imwrite " + filename + " (not an 8-bit grey image)");
  std::ofstream out(filename, std::ios::binary);
  if (!out) return false;
  out << "P5\n" << m.cols << " " << m.rows << "\n255\n";
  for (int y = 0; y < m.rows; ++y) out.write(m.ptr<char>(y), m.cols);
  return static_cast<bool>(out);
}

bool haveImageReader(const String& filename) { return IsPgm(filename); }
bool haveImageWriter(const String& filename) { return IsPgm(filename); }


// Encodes an 8-bit single-channel image as binary PGM (make-dataset encodes, then writes and
// fsyncs the bytes itself).
bool imencode(const String& ext, InputArray img, std::vector<uchar>& buf, const std::vector<int>& /*params*/) {
  if (ext != ".pgm") Refuse("imencode " + ext);
  const Mat m = img.getMat();
  if (m.type() != CV_8UC1) Refuse("imencode " + ext + " (not an 8-bit grey image)");
  const std::string header = "P5\n" + std::to_string(m.cols) + " " + std::to_string(m.rows) + "\n255\n";
  buf.assign(header.begin(), header.end());
  for (int y = 0; y < m.rows; ++y) buf.insert(buf.end(), m.ptr<uchar>(y), m.ptr<uchar>(y) + m.cols);
  return true;
}

}  // namespace cv
