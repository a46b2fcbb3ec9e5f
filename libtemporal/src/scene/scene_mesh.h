// Format-neutral helpers shared by the mesh readers (gltf_mesh.cpp, usd_mesh.cpp): vertex expansion,
// generated normals, skin weight normalisation, bounds, the default material. Internal to src/scene.
#pragma once

#include "scene_description.h"

#include <algorithm>
#include <cstdint>
#include <vector>

namespace temporal::scene_detail {

// out[i * per_vertex + c] = v[idx[i] * per_vertex + c]: per-vertex data re-indexed by `idx`.
template <typename T>
std::vector<T> expand(const std::vector<T>& v, const std::vector<std::uint32_t>& idx, std::size_t per_vertex) {
  std::vector<T> out(idx.size() * per_vertex);
  for (std::size_t i = 0; i < idx.size(); ++i) {
    std::copy_n(v.begin() + static_cast<std::ptrdiff_t>(idx[i] * per_vertex), per_vertex,
                out.begin() + static_cast<std::ptrdiff_t>(i * per_vertex));
  }
  return out;
}

// Flat normals (glTF 2.0 section 3.7.2.1 for primitives without normals): one vertex per triangle corner,
// every per-vertex array of `prim` and `data` expanded along the indices; sets data.flat_normals.
void make_flat_normals(ScenePrimitive& prim, PrimitiveData& data);
// Unit length; zero, NaN or infinite normals become (0, 0, 1).
void normalise_normals(std::vector<glm::vec3>& normals);
// Skin weights of each vertex scaled to sum 1; a vertex without weight follows its first joint.
void normalise_skin_weights(PrimitiveData& data, std::size_t vertex_count);
void compute_local_bounds(const ScenePrimitive& prim, PrimitiveData& data);
// Appends the grey (0.8) material named "default" given to primitives without one; returns its index.
int add_default_material(std::vector<SceneMaterial>& materials);

}  // namespace temporal::scene_detail
