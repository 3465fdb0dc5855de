#ifndef CLOTHWIND_DATA_PATHS_H_
#define CLOTHWIND_DATA_PATHS_H_

#include <string>

#include "render/render_params.h"

namespace clothwind::data {

// The package's config folder: $CLOTHWIND_SOURCE_DIR/config when that variable is set (tests,
// scripts/env.sh), else the source tree this library was built from.
std::string ConfigDir();

// config/scenes/flag.json or config/scenes/cloth.json.
std::string DefaultScenePath(render::SceneKind kind);

// Fabrics for ClothSim: $CLOTHWIND_SHARED_DIR/arcsim/materials when it exists (ArcSim's Wang et
// al. materials), else config/materials.
std::string DefaultMaterialsDir();

}  // namespace clothwind::data

#endif  // CLOTHWIND_DATA_PATHS_H_
