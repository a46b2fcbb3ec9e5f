// UsdaWriter: writes the glTF model a GltfBuilder assembled as a text USD layer (.usda) that replays the same
// scene: every node an Xform (translate / orient / scale ops, time samples from LINEAR channels; CUBICSPLINE
// channels baked to one sample every 1/120 s, so that 40 Hz and 120 Hz frames land on samples), meshes as
// UsdGeomMesh with vertex-interpolated normals and st (t = 1 - v), materials as UsdPreviewSurface with a
// UsdUVTexture whose scale is the base colour factor, skins as UsdSkel (SkelRoot at the skin's skeleton node,
// a Skeleton and a SkelAnimation), morph targets as blend shapes, cameras, distant and sphere lights.
// Textures are written beside the layer as PNG files (stb's encoder, as in the .glb).
//
// Timing: timeCodesPerSecond = framesPerSecond = 120, startTimeCode 0, endTimeCode = 120 * clip - 1, so the
// reader's clip duration ((end - start + tcps / fps) / tcps) equals the glTF clip's.
#pragma once

#include <tiny_gltf.h>

#include <string>
#include <vector>

namespace scenegen {

struct TextureFile {
  std::string path;                // relative to the layer, e.g. "textures/walkers.ground_checker.png"
  std::vector<unsigned char> png;  // encoded bytes
};

// The layer's text; `textures` receives the image files it references. Fails (empty string, message in
// `error`) on glTF features the built-in scenes do not use and the writer does not convert.
std::string write_usda(const tinygltf::Model& model, const std::string& scene_name, std::vector<TextureFile>& textures,
                       std::string& error);

}  // namespace scenegen
