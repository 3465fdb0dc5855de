#include "learn/weights_io.h"

#include <sstream>
#include <stdexcept>

#include <ATen/ATen.h>
#include <c10/util/Exception.h>
#include <torch/serialize/input-archive.h>
#include <torch/serialize/output-archive.h>

#include "learn/model_config.h"
#include "learn/zip_checksums.h"

namespace clothwind::learn {
namespace {

constexpr double kHalfMax = 65504.0;
// The archive key of SaveModuleWeights' metadata string: not a name torch gives a parameter,
// buffer or submodule of ours.
constexpr const char* kMetadataKey = "clothwind.metadata";

void Write(const torch::nn::Module& module, const std::string& prefix, WeightPrecision precision,
           torch::serialize::OutputArchive& archive) {
  for (const auto& item : module.named_parameters(/*recurse=*/false)) {
    at::Tensor t = item.value().detach().to(at::kCPU);
    if (precision == WeightPrecision::kFloat16 && t.is_floating_point()) {
      if (t.numel() > 0 && t.abs().max().item<double>() > kHalfMax) {
        throw std::runtime_error("parameter " + prefix + item.key() +
                                 " exceeds float16's range (65504); save it as float32");
      }
      t = t.to(at::kHalf);
    }
    archive.write(item.key(), t);
  }
  for (const auto& item : module.named_buffers(/*recurse=*/false)) {
    archive.write(item.key(), item.value().detach().to(at::kCPU), /*is_buffer=*/true);
  }
  for (const auto& child : module.named_children()) {
    if (!child.value()->is_serializable()) continue;  // as torch::save
    torch::serialize::OutputArchive child_archive(archive.compilation_unit());
    Write(*child.value(), prefix + child.key() + ".", precision, child_archive);
    archive.write(child.key(), child_archive);
  }
}

// Reads `key` from the archive and copies it into `target`, converting the dtype.
void ReadInto(torch::serialize::InputArchive& archive, const std::string& key, const std::string& name,
              bool is_buffer, at::Tensor& target, const std::filesystem::path& path, bool* any_half) {
  at::Tensor read;
  if (!archive.try_read(key, read, is_buffer)) {
    throw std::runtime_error(path.string() + ": no tensor " + name);
  }
  if (read.sizes() != target.sizes()) {
    std::ostringstream what;
    what << path.string() << ": tensor " << name << " is " << read.sizes() << ", the network expects "
         << target.sizes();
    throw std::runtime_error(what.str());
  }
  if (read.is_floating_point() != target.is_floating_point()) {
    throw std::runtime_error(path.string() + ": tensor " + name + " is " + std::string(read.dtype().name()) +
                             ", the network expects " + std::string(target.dtype().name()));
  }
  // The archive's checksums are not verified on load: corrupt bytes read as values, often NaN or
  // inf, and a model of them answers NaN for every clip (an evaluation then printed RMSE -nan
  // and exited 0). Weights and running statistics of a trained network are finite.
  if (read.is_floating_point() && !at::isfinite(read).all().item<bool>()) {
    throw std::runtime_error(path.string() + ": tensor " + name + " holds values that are not finite (a corrupt file?)");
  }
  if (read.scalar_type() == at::kHalf && !is_buffer) *any_half = true;
  at::NoGradGuard no_grad;
  target.copy_(read);
}

void Read(torch::nn::Module& module, const std::string& prefix, torch::serialize::InputArchive& archive,
          const std::filesystem::path& path, bool* any_half) {
  for (auto& item : module.named_parameters(/*recurse=*/false)) {
    ReadInto(archive, item.key(), prefix + item.key(), false, item.value(), path, any_half);
  }
  for (auto& item : module.named_buffers(/*recurse=*/false)) {
    ReadInto(archive, item.key(), prefix + item.key(), true, item.value(), path, any_half);
  }
  for (const auto& child : module.named_children()) {
    if (!child.value()->is_serializable()) continue;  // as torch::load
    torch::serialize::InputArchive child_archive;
    if (!archive.try_read(child.key(), child_archive)) {
      throw std::runtime_error(path.string() + ": no module " + prefix + child.key());
    }
    Read(*child.value(), prefix + child.key() + ".", child_archive, path, any_half);
  }
}

}  // namespace

std::string ToString(WeightPrecision precision) {
  return precision == WeightPrecision::kFloat16 ? "float16" : "float32";
}

WeightPrecision ParseWeightPrecision(const std::string& name) {
  if (name == "float32") return WeightPrecision::kFloat32;
  if (name == "float16") return WeightPrecision::kFloat16;
  throw std::invalid_argument("weight precision must be float32 or float16, got \"" + name + "\"");
}

std::string SerializeModuleWeights(const torch::nn::Module& module, WeightPrecision precision,
                                   const std::string& metadata) {
  torch::serialize::OutputArchive archive;
  Write(module, "", precision, archive);
  if (!metadata.empty()) archive.write(kMetadataKey, c10::IValue(metadata));
  std::ostringstream bytes;
  archive.save_to(bytes);
  return bytes.str();
}

void SaveModuleWeights(const torch::nn::Module& module, const std::filesystem::path& path,
                       WeightPrecision precision, const std::string& metadata) {
  WriteFileAtomically(path, SerializeModuleWeights(module, precision, metadata));
}

WeightPrecision LoadModuleWeights(torch::nn::Module& module, const std::filesystem::path& path,
                                  std::string* metadata) {
  if (!std::filesystem::exists(path)) throw std::runtime_error(path.string() + ": no such file");
  torch::serialize::InputArchive archive;
  try {
    archive.load_from(path.string(), at::Device(at::kCPU));
  } catch (const c10::Error& e) {
    throw std::runtime_error(path.string() + ": not a torch weights file: " + e.what_without_backtrace());
  }
  // An archive libtorch reads, checked entry by entry before its tensors are trusted (libtorch
  // does not check the checksums: learn/zip_checksums.h).
  VerifyZipChecksums(path);
  bool any_half = false;
  try {
    Read(module, "", archive, path, &any_half);
    if (metadata) {
      c10::IValue stored;
      *metadata = archive.try_read(kMetadataKey, stored) && stored.isString() ? stored.toStringRef() : "";
    }
  } catch (const c10::Error& e) {
    throw std::runtime_error(path.string() + ": " + e.what_without_backtrace());
  }
  return any_half ? WeightPrecision::kFloat16 : WeightPrecision::kFloat32;
}

}  // namespace clothwind::learn
