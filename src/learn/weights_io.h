// Reading and writing a module's weights in float32 or float16 (half the file, for shipping).
//
// torch::save/torch::load keep each tensor's dtype, and torch::load into a float32 module
// reinterprets a float16 file's bytes rather than converting them (garbage weights, no error).
// These functions walk the module as torch::save does (parameters, buffers, then children under
// their names, the same archive layout) but convert floating-point tensors on the way in and
// out, and check every tensor's shape against the module's.
#ifndef CLOTHWIND_LEARN_WEIGHTS_IO_H_
#define CLOTHWIND_LEARN_WEIGHTS_IO_H_

#include <filesystem>
#include <string>

#include <torch/nn/module.h>

namespace clothwind::learn {

enum class WeightPrecision { kFloat32, kFloat16 };

// "float32" / "float16"; ParseWeightPrecision throws std::invalid_argument for anything else.
std::string ToString(WeightPrecision precision);
WeightPrecision ParseWeightPrecision(const std::string& name);

// Writes the module's parameters (float16 when asked) and buffers (always as they are: batch
// norm statistics are few and may exceed float16's range) to `path` atomically (temporary
// file, then rename).
// Inputs: module  any torch module on any device; path  destination file;
//   precision  of the floating-point parameters in the file.
//   metadata  a string stored with the weights (empty: none), read back by LoadModuleWeights;
//     SaveWindNet stores the network's configuration there, so that the weights know what they
//     were trained as even when the JSON beside them is edited or swapped.
// Throws std::runtime_error naming the tensor if a parameter is not finite in float16
// (|x| > 65504), so a file is never written with weights that would not load as they were.
void SaveModuleWeights(const torch::nn::Module& module, const std::filesystem::path& path,
                       WeightPrecision precision, const std::string& metadata = "");

// The bytes SaveModuleWeights writes (for a caller that writes them with another file as a pair:
// WriteFilePairAtomically). Same inputs and throws, less the path.
std::string SerializeModuleWeights(const torch::nn::Module& module, WeightPrecision precision,
                                   const std::string& metadata = "");

// Reads a file written by SaveModuleWeights or torch::save into `module` (on the CPU),
// converting floating-point tensors to the module's dtype.
// Outputs: the precision the file's parameters were stored in; *metadata (when not null) the
//   string saved with them, empty for a file written without one (or by torch::save).
// Throws std::runtime_error naming `path` and the tensor when one is missing, has another
// shape, or mixes integer and floating point with the module's.
WeightPrecision LoadModuleWeights(torch::nn::Module& module, const std::filesystem::path& path,
                                  std::string* metadata = nullptr);

}  // namespace clothwind::learn

#endif  // CLOTHWIND_LEARN_WEIGHTS_IO_H_
