// Format-neutral mesh helpers (scene_mesh.h).
#include "scene_mesh.h"

#include <cmath>
#include <limits>
#include <numeric>

namespace temporal::scene_detail {

// Primitives without normals get flat normals (glTF 2.0 section 3.7.2.1), which need one vertex per
// triangle corner: every per-vertex array is expanded along the indices.
void make_flat_normals(ScenePrimitive& prim, PrimitiveData& data) {
  const auto& ix = prim.indices;
  prim.positions = expand(prim.positions, ix, 1);
  if (!prim.texcoords.empty()) prim.texcoords = expand(prim.texcoords, ix, 1);
  if (data.influences > 0) {
    data.joints = expand(data.joints, ix, static_cast<std::size_t>(data.influences));
    data.weights = expand(data.weights, ix, static_cast<std::size_t>(data.influences));
  }
  for (auto& tp : data.target_positions) tp = expand(tp, ix, 1);
  for (auto& tn : data.target_normals) {
    if (!tn.empty()) tn = expand(tn, ix, 1);
  }
  if (!data.vertex_point.empty()) data.vertex_point = expand(data.vertex_point, ix, 1);
  prim.normals.resize(prim.positions.size());
  for (std::size_t tri = 0; tri + 2 < prim.positions.size(); tri += 3) {
    const glm::vec3 e1 = prim.positions[tri + 1] - prim.positions[tri];
    const glm::vec3 e2 = prim.positions[tri + 2] - prim.positions[tri];
    glm::vec3 nn = glm::cross(e1, e2);
    const float len = glm::length(nn);
    nn = len > 0.0f ? nn / len : glm::vec3(0.0f, 0.0f, 1.0f);
    prim.normals[tri] = prim.normals[tri + 1] = prim.normals[tri + 2] = nn;
  }
  prim.indices.resize(prim.positions.size());
  std::iota(prim.indices.begin(), prim.indices.end(), 0u);
  data.flat_normals = true;
}

void normalise_normals(std::vector<glm::vec3>& normals) {
  for (auto& nn : normals) {
    const float len = glm::length(nn);
    nn = (len > 0.0f && std::isfinite(len)) ? nn / len : glm::vec3(0.0f, 0.0f, 1.0f);
  }
}

void normalise_skin_weights(PrimitiveData& data, std::size_t vertex_count) {
  if (data.influences <= 0) return;
  const auto m = static_cast<std::size_t>(data.influences);
  for (std::size_t v = 0; v < vertex_count; ++v) {
    float sum = 0.0f;
    for (std::size_t c = 0; c < m; ++c) sum += data.weights[v * m + c];
    if (sum > 0.0f) {
      for (std::size_t c = 0; c < m; ++c) data.weights[v * m + c] /= sum;
    } else {
      data.weights[v * m] = 1.0f;  // no influence: follows the first joint
    }
  }
}

void compute_local_bounds(const ScenePrimitive& prim, PrimitiveData& data) {
  data.local_min = glm::vec3(std::numeric_limits<float>::max());
  data.local_max = glm::vec3(std::numeric_limits<float>::lowest());
  for (const auto& p : prim.positions) {
    data.local_min = glm::min(data.local_min, p);
    data.local_max = glm::max(data.local_max, p);
  }
}

int add_default_material(std::vector<SceneMaterial>& materials) {
  SceneMaterial def;
  def.name = "default";
  def.base_color_factor = glm::vec4(0.8f, 0.8f, 0.8f, 1.0f);
  materials.push_back(def);
  return static_cast<int>(materials.size()) - 1;
}

}  // namespace temporal::scene_detail
