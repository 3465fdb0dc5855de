#ifndef CLOTHWIND_DATA_PATHS_H_
#define CLOTHWIND_DATA_PATHS_H_

#include <filesystem>
#include <string>

#include "render/render_params.h"

namespace clothwind::data {

// The package's config folder, the first of:
//   1. $CLOTHWIND_SOURCE_DIR/config when that variable is set and the folder exists (tests,
//      scripts/env.sh);
//   2. <prefix>/share/clothwind/config when the running program is <prefix>/bin/<name> or
//      <prefix>/lib/clothwind/<name> and that folder exists (an install space, which may have
//      been moved, or a Debian package of it);
//   3. the source tree this library was built from.
std::string ConfigDir();

// ConfigDir's rule with its inputs named, so that tests can give them.
//   source_dir  $CLOTHWIND_SOURCE_DIR, or empty
//   executable  the running program's path (/proc/self/exe), or empty when unknown
//   built_in    the config folder of the source tree built from
// Returns the folder the rule picks (rule 3 even when built_in does not exist).
std::string ConfigDirFor(const std::string& source_dir, const std::filesystem::path& executable,
                         const std::string& built_in);

// config/scenes/flag.json or config/scenes/cloth.json.
std::string DefaultScenePath(render::SceneKind kind);

// Fabrics for ClothSim: $CLOTHWIND_SHARED_DIR/arcsim/materials when it exists (ArcSim's Wang et
// al. materials), else config/materials.
std::string DefaultMaterialsDir();

}  // namespace clothwind::data

#endif  // CLOTHWIND_DATA_PATHS_H_
