// The weights archive's checksums: a byte changed anywhere in an entry's data is found and named
// with its entry, an intact archive passes, a cut or foreign file is refused naming the file, and a
// damaged model is refused by LoadModuleWeights (it loaded and answered other figures).
#include "learn/zip_checksums.h"

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>
#include <torch/torch.h>

#include "learn/weights_io.h"

namespace clothwind::learn {
namespace {
namespace fs = std::filesystem;

std::string Refusal(const fs::path& path) {
  try {
    VerifyZipChecksums(path);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "accepted";
}

std::string Bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void Write(const fs::path& p, const std::string& bytes) { std::ofstream(p, std::ios::binary) << bytes; }

class ZipChecksumsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("clothwind_zip_checksums_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    torch::manual_seed(3);
    SaveModuleWeights(*linear_, dir_ / "w.pt", WeightPrecision::kFloat32, "{\"a\": 1}");
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
  torch::nn::Linear linear_{torch::nn::LinearOptions(64, 32)};  // 8 kB of weights: one entry
};

TEST_F(ZipChecksumsTest, AnIntactArchivePassesAndEveryChangedByteOfTheWeightsIsNamedWithItsEntry) {
  EXPECT_EQ(Refusal(dir_ / "w.pt"), "accepted");
  const std::string good = Bytes(dir_ / "w.pt");
  // The weight tensor's data: the 8192 bytes of 2048 floats, found by their first value.
  const at::Tensor w = linear_->weight.detach().contiguous();
  const std::string first(reinterpret_cast<const char*>(w.data_ptr<float>()), 16);
  const size_t data = good.find(first);
  ASSERT_NE(data, std::string::npos);
  for (const size_t offset : {size_t{0}, size_t{4097}, size_t{8191}}) {
    std::string bad = good;
    bad[data + offset] ^= 0x80;  // a sign bit: the value stays finite
    Write(dir_ / "bad.pt", bad);
    const std::string why = Refusal(dir_ / "bad.pt");
    EXPECT_NE(why.find((dir_ / "bad.pt").string() + ": entry "), std::string::npos) << why;
    EXPECT_NE(why.find("fails its checksum"), std::string::npos) << why;
    EXPECT_NE(why.find("data/"), std::string::npos) << "names the tensor's entry: " << why;
    // And the model loader refuses it: it loaded, and its values were other weights.
    torch::nn::Linear into(torch::nn::LinearOptions(64, 32));
    try {
      LoadModuleWeights(*into, dir_ / "bad.pt");
      ADD_FAILURE() << "a damaged weights file loaded (byte " << offset << ")";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("fails its checksum"), std::string::npos) << e.what();
    }
  }
}

TEST_F(ZipChecksumsTest, ACutOrForeignFileIsRefusedNamingIt) {
  const std::string good = Bytes(dir_ / "w.pt");
  Write(dir_ / "cut.pt", good.substr(0, good.size() - 10));
  EXPECT_NE(Refusal(dir_ / "cut.pt").find((dir_ / "cut.pt").string() + ": not a ZIP archive"), std::string::npos)
      << Refusal(dir_ / "cut.pt");
  Write(dir_ / "text.pt", "hello");
  EXPECT_NE(Refusal(dir_ / "text.pt").find("text.pt: not a ZIP archive (5 bytes)"), std::string::npos)
      << Refusal(dir_ / "text.pt");
  // The directory says more entries than it holds (a damaged end record).
  std::string lying = good;
  const size_t end = lying.rfind(std::string("PK\x05\x06", 4));
  ASSERT_NE(end, std::string::npos);
  lying[end + 10] = static_cast<char>(static_cast<unsigned char>(lying[end + 10]) + 1);
  Write(dir_ / "lying.pt", lying);
  EXPECT_NE(Refusal(dir_ / "lying.pt").find("lying.pt: "), std::string::npos);
  EXPECT_NE(Refusal(dir_ / "lying.pt"), "accepted");
}

TEST_F(ZipChecksumsTest, TheShippedModelPasses) {
  const char* source = std::getenv("CLOTHWIND_SOURCE_DIR");
  ASSERT_NE(source, nullptr) << "CLOTHWIND_SOURCE_DIR is set by CTest";
  for (const char* name : {"sdn.pt", "fly_judge.pt"}) EXPECT_EQ(Refusal(fs::path(source) / "models" / name), "accepted");
}

}  // namespace
}  // namespace clothwind::learn
