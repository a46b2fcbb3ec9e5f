// Procedural building blocks of the built-in scenes: meshes (boxes, cylinders, planes, grids, cones) and
// RGBA textures (checkers, bricks, leaves), all deterministic.
#pragma once

#include "gltf_builder.h"

#include <cstdint>

namespace scenegen {

// Axis-aligned box centred at the origin with the given full size; per-face normals and 0..1 UVs.
// `segments_y` > 1 splits the four side faces along Y (so a skinned leg can bend).
MeshData box(const glm::vec3& size, int segments_y = 1);
// Cylinder along +Y from y = 0 to `height`, `segments` around, with caps; UV u around, v up.
MeshData cylinder(float radius, float height, int segments, bool caps = true);
// Cone along +Y from y = 0 (base) to `height` (apex).
MeshData cone(float radius, float height, int segments);
// Horizontal square plane at y = 0 facing +Y, `size` wide, UVs 0..uv_repeat, split into n x n quads.
MeshData plane(float size, float uv_repeat, int n = 1);
// Vertical quad in the XY plane facing +Z, centred at the origin (for cut-out foliage cards).
MeshData quad(float width, float height);

// Deterministic hash to [0, 1) (no library random generator: their sequences differ between implementations).
float hash01(std::uint32_t a, std::uint32_t b = 0);

// Checkerboard: `squares` x `squares` cells of `size` x `size` pixels.
TextureDesc checker(const std::string& name, int size, int squares, glm::vec3 a, glm::vec3 b);
// Bricks with mortar lines and per-brick tint.
TextureDesc bricks(const std::string& name, int size, int rows, glm::vec3 brick, glm::vec3 mortar);
// Leaf atlas: green leaf ellipses on transparent background (alpha 0 or 255), for alpha MASK cut-outs.
TextureDesc leaves(const std::string& name, int size, int count);

// Quaternion that turns -Z towards `forward` with +Y up (cameras and lights look down their -Z).
glm::quat look_rotation(const glm::vec3& forward, const glm::vec3& up = glm::vec3(0.0f, 1.0f, 0.0f));
// Appends a quaternion (x, y, z, w) to `out`, flipped to the hemisphere of the previous one so that
// consecutive keys are interpolated along the short arc.
void push_quat(std::vector<float>& out, glm::quat q);

}  // namespace scenegen
