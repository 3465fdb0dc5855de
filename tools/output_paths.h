// Refusing an output path that would overwrite one of a verb's inputs. Why: `eval --plot
// run/model.pt`, `--json run/model.json` or `--json data/index.json`, and `export-model --out`
// or `train-fly-judge --out` whose card lands on an input's, exited 0 having replaced the
// user's model, its configuration or a dataset's index.
#ifndef CLOTHWIND_TOOLS_OUTPUT_PATHS_H_
#define CLOTHWIND_TOOLS_OUTPUT_PATHS_H_

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "common/atomic_file.h"
#include "usage_error.h"

namespace clothwind::tools {

// Whether two paths name one file: equivalent when both exist, else equal once made absolute and
// normal (an output not written yet).
inline bool SameFile(const std::filesystem::path& a, const std::filesystem::path& b) {
  std::error_code ec;
  if (std::filesystem::exists(a, ec) && std::filesystem::exists(b, ec)) return std::filesystem::equivalent(a, b, ec);
  return std::filesystem::absolute(a).lexically_normal() == std::filesystem::absolute(b).lexically_normal();
}

// Throws UsageError naming `option` and the input when `output` (empty: none) is one
// of `inputs` (the files the verb reads: a model, its .json, a dataset's index.json, ...).
inline void RefuseOutputOverInput(const std::string& option, const std::filesystem::path& output,
                                  const std::vector<std::filesystem::path>& inputs) {
  if (output.empty()) return;
  for (const auto& input : inputs)
    if (!input.empty() && SameFile(output, input))
      throw UsageError(option + " " + output.string() + " is an input (" + input.string() +
                                  "); write it elsewhere");
}

// Throws UsageError naming `option` when `output` is a folder: the verbs that make a
// missing output folder themselves failed only when saving, after the work.
inline void RefuseFolderAsOutput(const std::string& option, const std::filesystem::path& output) {
  std::error_code ec;
  if (!output.empty() && std::filesystem::is_directory(output, ec))
    throw UsageError(option + " " + output.string() + " is a folder; expected a file name");
}

// `p` absolute, with symbolic links resolved where they exist, and normal: the form IsAtOrInside
// compares.
inline std::filesystem::path NormalPath(const std::filesystem::path& p) {
  std::error_code ec;
  // Absolute first: weakly_canonical("run") of a missing relative path stays relative.
  const std::filesystem::path a = std::filesystem::absolute(p, ec);
  const std::filesystem::path c = std::filesystem::weakly_canonical(a, ec);
  return (ec ? a : c).lexically_normal();
}

// Whether `path` is `folder` or lies inside it, compared as NormalPath.
inline bool IsAtOrInside(const std::filesystem::path& path, const std::filesystem::path& folder) {
  const std::filesystem::path out = NormalPath(path), in = NormalPath(folder);
  return std::mismatch(in.begin(), in.end(), out.begin(), out.end()).first == in.end();
}

// Throws UsageError naming `option` when `output` is `folder` or lies inside it: `train
// --out DATA` wrote its run among the dataset's clips.
inline void RefuseOutputInsideFolder(const std::string& option, const std::filesystem::path& output,
                                     const std::filesystem::path& folder, const std::string& what) {
  if (output.empty() || folder.empty() || !IsAtOrInside(output, folder)) return;
  const bool same = IsAtOrInside(folder, output);
  throw UsageError(option + " " + output.string() + " is " + (same ? "" : "inside ") + what + " " + folder.string() +
                   "; write it elsewhere");
}

// Throws UsageError naming `option` (and `shown`, what was given) unless a file can be made in
// `folder`, or in the nearest folder above it that exists (the verbs make the missing ones):
// a file is made and removed there. A dangling symbolic link on the way is no folder that exists
// (`exists` follows it, and the work failed later with "cannot create directories: File exists").
inline void RefuseUnwritableIn(const std::string& option, const std::string& shown, std::filesystem::path folder) {
  std::error_code ec;
  folder = std::filesystem::absolute(folder, ec);
  while (!folder.empty() && !std::filesystem::exists(std::filesystem::symlink_status(folder, ec)) &&
         folder != folder.parent_path())
    folder = folder.parent_path();
  if (!std::filesystem::is_directory(folder, ec))
    throw UsageError(option + " " + shown + ": " + folder.string() +
                     (std::filesystem::is_symlink(std::filesystem::symlink_status(folder, ec))
                          ? " is a symbolic link to nothing"
                          : " is a file, not a folder"));
  const std::string probe = TemporaryNameFor((folder / ".clothwind-write-probe").string());
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0)
    throw UsageError(option + " " + shown + ": cannot write in " + folder.string() + " (" + std::strerror(errno) + ")");
  ::close(fd);
  ::unlink(probe.c_str());
}

// Throws UsageError naming `option` when no file can be made where the file `output` (empty:
// none) goes (RefuseUnwritableIn of its folder). `eval --json /proc/x.json` ran the whole
// evaluation and then failed to write.
inline void RefuseUnwritableFolder(const std::string& option, const std::filesystem::path& output) {
  if (output.empty()) return;
  std::error_code ec;
  RefuseUnwritableIn(option, output.string(), std::filesystem::absolute(output, ec).parent_path());
}

// Throws UsageError naming `option` unless `output` (empty: none) could be written: it is not a
// folder itself, and its folder, or the nearest one above it that exists, takes a new file (the
// verb makes the missing folders with MakeFoldersFor, as every verb does for its outputs: eval
// and contact-sheet refused a missing one where simulate, render, train and export-model made
// it). Checked before the work, which used to run to its end (a whole evaluation) and then fail
// to write or, for a plot, exit 0.
inline void RefuseUnwritableOutput(const std::string& option, const std::filesystem::path& output) {
  if (output.empty()) return;
  RefuseFolderAsOutput(option, output);
  RefuseUnwritableFolder(option, output);
}

// The folders MakeFoldersFor made, outermost first. Unless Keep() is called, the ones still empty
// are removed again when it goes (innermost first; a folder something was written into stays):
// a verb that failed, or found nothing to write (contact-sheet of a dataset without clips), left
// the empty folders of its output behind.
class MadeFolders {
 public:
  MadeFolders() = default;
  explicit MadeFolders(std::vector<std::filesystem::path> made) : made_(std::move(made)) {}
  MadeFolders(MadeFolders&& other) noexcept : made_(std::move(other.made_)) { other.made_.clear(); }
  MadeFolders& operator=(MadeFolders&& other) noexcept {
    if (this != &other) {
      RemoveEmpty();
      made_ = std::move(other.made_);
      other.made_.clear();
    }
    return *this;
  }
  MadeFolders(const MadeFolders&) = delete;
  MadeFolders& operator=(const MadeFolders&) = delete;
  ~MadeFolders() { RemoveEmpty(); }

  // The output was written: its folders stay.
  void Keep() { made_.clear(); }
  const std::vector<std::filesystem::path>& made() const { return made_; }

 private:
  void RemoveEmpty() {
    for (auto it = made_.rbegin(); it != made_.rend(); ++it) {
      std::error_code ec;
      if (std::filesystem::is_empty(*it, ec) && !ec) std::filesystem::remove(*it, ec);
    }
    made_.clear();
  }

  std::vector<std::filesystem::path> made_;
};

// Makes the missing folders `output` (a file; empty: none) goes in, as `mkdir -p` its folder; the
// verbs call it once the checks pass, before the work (made after it, a failure lost the work).
// Returns the folders it made (MadeFolders: removed again, if still empty, unless kept).
// Throws std::runtime_error naming `option`, the output and the folder when they cannot be made.
[[nodiscard]] inline MadeFolders MakeFoldersFor(const std::string& option, const std::filesystem::path& output) {
  if (output.empty()) return {};
  std::error_code ec;
  const std::filesystem::path folder = std::filesystem::absolute(output, ec).parent_path();
  std::vector<std::filesystem::path> missing;
  std::error_code missing_ec;  // symlink_status reports a missing path in it too
  if (!ec)
    for (std::filesystem::path f = folder;
         !f.empty() && f != f.parent_path() &&
         !std::filesystem::exists(std::filesystem::symlink_status(f, missing_ec));
         f = f.parent_path())
      missing.insert(missing.begin(), f);
  if (!ec) std::filesystem::create_directories(folder, ec);
  if (ec)
    throw std::runtime_error(option + " " + output.string() + ": cannot make its folder " + folder.string() + " (" +
                             ec.message() + ")");
  return MadeFolders(std::move(missing));
}

// Makes `output`'s folder again if it went while the verb worked (errors are left to the write
// that follows, which names them). Why: runs of a sweep share a new results folder, and one that
// failed took it away again, still empty (MadeFolders), while another worked towards writing
// into it: that one's whole evaluation was lost at its write.
inline void RemakeFolderFor(const std::filesystem::path& output) {
  if (output.empty()) return;
  std::error_code ec;
  const std::filesystem::path folder = std::filesystem::absolute(output, ec).parent_path();
  if (!ec) std::filesystem::create_directories(folder, ec);
}

// Throws UsageError naming `option` unless files can be made in the folder `output_folder` (made
// later if missing; RefuseUnwritableIn): `--out /proc/x` failed with "filesystem error: cannot
// create directories: ... [/proc/x]", naming no option.
inline void RefuseUnwritableOutputFolder(const std::string& option, const std::filesystem::path& output_folder) {
  if (!output_folder.empty()) RefuseUnwritableIn(option, output_folder.string(), output_folder);
}

// Throws UsageError naming `option` and the file when one of `outputs` exists and `overwrite` is
// false: the verbs that write a model or a judge replace one only with --overwrite, as
// make-session a bag and train a run (`export-model --out models/sdn.pt` replaced the shipped
// model without a word).
inline void RefuseExistingOutput(const std::string& option, const std::vector<std::filesystem::path>& outputs,
                                 bool overwrite) {
  if (overwrite) return;
  for (const auto& output : outputs) {
    std::error_code ec;
    if (std::filesystem::exists(output, ec))
      throw UsageError(option + ": " + output.string() + " exists; --overwrite replaces it");
  }
}

}  // namespace clothwind::tools

#endif  // CLOTHWIND_TOOLS_OUTPUT_PATHS_H_
