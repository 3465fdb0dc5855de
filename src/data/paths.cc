#include "data/paths.h"

#include <cstdlib>
#include <filesystem>

#ifndef CLOTHWIND_DEFAULT_CONFIG_DIR
#define CLOTHWIND_DEFAULT_CONFIG_DIR "config"
#endif

namespace clothwind::data {

namespace fs = std::filesystem;

std::string ConfigDir() {
  if (const char* src = std::getenv("CLOTHWIND_SOURCE_DIR"); src && *src) {
    const fs::path p = fs::path(src) / "config";
    if (fs::is_directory(p)) return p.string();
  }
  return CLOTHWIND_DEFAULT_CONFIG_DIR;
}

std::string DefaultScenePath(render::SceneKind kind) {
  return (fs::path(ConfigDir()) / "scenes" / (render::SceneKindName(kind) + ".json")).string();
}

std::string DefaultMaterialsDir() {
  if (const char* shared = std::getenv("CLOTHWIND_SHARED_DIR"); shared && *shared) {
    const fs::path p = fs::path(shared) / "arcsim" / "materials";
    if (fs::is_directory(p)) return p.string();
  }
  return (fs::path(ConfigDir()) / "materials").string();
}

}  // namespace clothwind::data
