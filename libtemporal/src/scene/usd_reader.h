// The text USD reader: parses .usda layers (usda_parser.h), composes them into a stage (usd_stage.h) and
// translates UsdGeom, UsdShade, UsdLux and UsdSkel prims into the format-neutral SceneDescription
// (docs/usd.md lists every schema and property read, and what is refused). Internal to src/scene.
#pragma once

#include "scene_description.h"

#include <string>

namespace temporal::scene_detail {

// Fills `out` from the text USD layer at `path` and everything it composes.
Status read_usd(const std::string& path, const SceneLoadOptions& options, SceneDescription& out);

}  // namespace temporal::scene_detail
