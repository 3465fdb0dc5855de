#include "data/paths.h"

#include <cstdlib>
#include <system_error>

#ifndef CLOTHWIND_DEFAULT_CONFIG_DIR
#define CLOTHWIND_DEFAULT_CONFIG_DIR "config"
#endif

namespace clothwind::data {

namespace fs = std::filesystem;

namespace {

bool IsDirectory(const fs::path& p) {
  std::error_code ec;
  return fs::is_directory(p, ec);
}

}  // namespace

std::string ConfigDirFor(const std::string& source_dir, const fs::path& executable,
                         const std::string& built_in) {
  if (!source_dir.empty() && IsDirectory(fs::path(source_dir) / "config")) {
    return (fs::path(source_dir) / "config").string();
  }
  if (!executable.empty()) {
    // catkin installs the CLI in <prefix>/bin and the nodes in <prefix>/lib/clothwind; both
    // find the package's share folder from there, wherever the prefix now is.
    const fs::path dir = executable.parent_path();
    for (const fs::path& prefix : {dir.parent_path(), dir.parent_path().parent_path()}) {
      const fs::path installed = prefix / "share" / "clothwind" / "config";
      if (IsDirectory(installed)) return installed.string();
    }
  }
  return built_in;
}

std::string ConfigDir() {
  const char* src = std::getenv("CLOTHWIND_SOURCE_DIR");
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  return ConfigDirFor(src ? src : "", ec ? fs::path() : exe, CLOTHWIND_DEFAULT_CONFIG_DIR);
}

std::string DefaultScenePath(render::SceneKind kind) {
  return (fs::path(ConfigDir()) / "scenes" / (render::SceneKindName(kind) + ".json")).string();
}

std::string DefaultMaterialsDir() {
  if (const char* shared = std::getenv("CLOTHWIND_SHARED_DIR"); shared && *shared) {
    const fs::path p = fs::path(shared) / "arcsim" / "materials";
    if (IsDirectory(p)) return p.string();
  }
  return (fs::path(ConfigDir()) / "materials").string();
}

}  // namespace clothwind::data
