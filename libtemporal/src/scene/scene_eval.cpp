// Scene::evaluate: animation channels -> local transforms -> world matrices (parents first) -> rigid
// instances (a model matrix) or deformed ones (morph targets, then linear blend skinning, on the CPU).
#include "scene_impl.h"

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>

namespace temporal {

using scene_detail::Impl;
using scene_detail::PrimitiveData;

Scene::Scene() : impl_(std::make_unique<Impl>()) {}
Scene::Scene(Scene&&) noexcept = default;
Scene& Scene::operator=(Scene&&) noexcept = default;
Scene::~Scene() = default;

std::vector<std::string> Scene::clip_names() const { return impl_->clip_names; }

std::vector<std::string> Scene::camera_names() const {
  std::vector<std::string> names;
  for (const auto& c : impl_->cameras) names.push_back(c.name + (c.orthographic ? " (orthographic)" : ""));
  return names;
}

const std::vector<std::string>& Scene::warnings() const { return impl_->warnings; }

FrameState Scene::evaluate(double time_s) const {
  FrameState f;
  evaluate(time_s, f);
  return f;
}

namespace {

glm::mat4 compose(const glm::vec3& t, const glm::quat& r, const glm::vec3& s) {
  // T * R * S (glTF 2.0 section 3.5.3), written out to avoid three 4x4 products.
  glm::mat4 m = glm::mat4_cast(r);
  m[0] *= s.x;
  m[1] *= s.y;
  m[2] *= s.z;
  m[3] = glm::vec4(t, 1.0f);
  return m;
}

// Transforms a normal by the inverse transpose of m's upper 3x3 up to a positive factor: the cofactor
// matrix (columns b x c, c x a, a x b for columns a, b, c), sign-corrected for mirroring transforms.
glm::vec3 transform_normal(const glm::mat4& m, const glm::vec3& n) {
  const glm::vec3 a(m[0]), b(m[1]), c(m[2]);
  const glm::vec3 bc = glm::cross(b, c), ca = glm::cross(c, a), ab = glm::cross(a, b);
  const float det = glm::dot(a, bc);
  const glm::vec3 r = n.x * bc + n.y * ca + n.z * ab;
  return det < 0.0f ? -r : r;
}

glm::vec3 safe_normalize(const glm::vec3& v) {
  const float len = glm::length(v);
  return len > 0.0f ? v / len : glm::vec3(0.0f, 0.0f, 1.0f);
}

}  // namespace

void Scene::evaluate(double time_s, FrameState& out) const {
  const Impl& m = *impl_;
  out.time = time_s;
  const std::size_t n_nodes = m.nodes.size();

  // Animation time wraps at the clip's end so sequences may run longer than the clip.
  double ta = time_s;
  if (clip_duration_ > 0.0) {
    ta = std::fmod(time_s, clip_duration_);
    if (ta < 0.0) ta += clip_duration_;
  }

  // Local transforms and morph weights: rest values overridden by the clip's channels.
  std::vector<glm::vec3> translation(n_nodes), scale(n_nodes);
  std::vector<glm::quat> rotation(n_nodes);
  std::vector<float> weights(static_cast<std::size_t>(m.weight_total));
  for (std::size_t i = 0; i < n_nodes; ++i) {
    const scene_detail::Node& n = m.nodes[i];
    translation[i] = n.translation;
    rotation[i] = n.rotation;
    scale[i] = n.scale;
    if (n.weight_count > 0) std::copy(n.rest_weights.begin(), n.rest_weights.end(), weights.begin() + n.weight_offset);
  }
  std::vector<float> value;
  for (const scene_detail::Channel& ch : m.channels) {
    const scene_detail::Sampler& s = m.samplers[static_cast<std::size_t>(ch.sampler)];
    value.resize(static_cast<std::size_t>(s.components));
    const auto node = static_cast<std::size_t>(ch.node);
    switch (ch.path) {
      case scene_detail::TargetPath::Translation:
        scene_detail::sample(s, static_cast<float>(ta), false, value.data());
        translation[node] = glm::vec3(value[0], value[1], value[2]);
        break;
      case scene_detail::TargetPath::Scale:
        scene_detail::sample(s, static_cast<float>(ta), false, value.data());
        scale[node] = glm::vec3(value[0], value[1], value[2]);
        break;
      case scene_detail::TargetPath::Rotation:
        scene_detail::sample(s, static_cast<float>(ta), true, value.data());
        rotation[node] = glm::quat(value[3], value[0], value[1], value[2]);  // glTF stores x, y, z, w
        break;
      case scene_detail::TargetPath::Weights:
        scene_detail::sample(s, static_cast<float>(ta), false, value.data());
        std::copy(value.begin(), value.end(), weights.begin() + m.nodes[node].weight_offset);
        break;
    }
  }

  // World matrices, parents first.
  std::vector<glm::mat4> world(n_nodes);
  for (int v : m.order) {
    const auto i = static_cast<std::size_t>(v);
    const scene_detail::Node& n = m.nodes[i];
    const glm::mat4 local = n.use_matrix ? n.matrix : compose(translation[i], rotation[i], scale[i]);
    world[i] = n.parent >= 0 ? world[static_cast<std::size_t>(n.parent)] * local : local;
  }

  // Joint matrices of every skin (section 3.7.3.1): world(joint) * inverseBind(joint).
  std::vector<std::vector<glm::mat4>> joint_matrices(m.skins.size());
  for (std::size_t s = 0; s < m.skins.size(); ++s) {
    const scene_detail::Skin& skin = m.skins[s];
    joint_matrices[s].resize(skin.joints.size());
    for (std::size_t j = 0; j < skin.joints.size(); ++j) {
      joint_matrices[s][j] = world[static_cast<std::size_t>(skin.joints[j])] * skin.inverse_bind[j];
    }
  }

  out.instances.resize(m.draws.size());
  for (std::size_t d = 0; d < m.draws.size(); ++d) {
    const scene_detail::Draw& draw = m.draws[d];
    const scene_detail::Node& node = m.nodes[static_cast<std::size_t>(draw.node)];
    const ScenePrimitive& prim = primitives_[static_cast<std::size_t>(draw.primitive)];
    const PrimitiveData& pd = m.primitive_data[static_cast<std::size_t>(draw.primitive)];
    PrimitiveInstance& inst = out.instances[d];
    inst.primitive = draw.primitive;
    inst.node = draw.node;
    inst.id = static_cast<std::uint32_t>(prim.material + 1);
    inst.model = world[static_cast<std::size_t>(draw.node)];
    const bool skinned = node.skin >= 0 && pd.influences > 0;
    const bool morphed = !pd.target_positions.empty() && node.weight_count > 0;
    inst.deformed = skinned || morphed;
    if (!inst.deformed) {
      inst.world_positions.clear();
      inst.world_normals.clear();
      continue;
    }
    const std::size_t nv = prim.positions.size();
    inst.world_positions.resize(nv);
    inst.world_normals.resize(nv);
    const float* w = morphed ? weights.data() + node.weight_offset : nullptr;
    const std::size_t n_targets = morphed ? std::min(pd.target_positions.size(), static_cast<std::size_t>(node.weight_count)) : 0;
    const glm::mat4* joints = skinned ? joint_matrices[static_cast<std::size_t>(node.skin)].data() : nullptr;
    const auto influences = static_cast<std::size_t>(pd.influences);
    for (std::size_t v = 0; v < nv; ++v) {
      glm::vec3 p = prim.positions[v];
      glm::vec3 nrm = prim.normals[v];
      // Morph targets first (section 3.7.2.2): rest + sum_k w_k * delta_k.
      for (std::size_t k = 0; k < n_targets; ++k) {
        if (w[k] == 0.0f) continue;
        p += w[k] * pd.target_positions[k][v];
        if (!pd.target_normals[k].empty()) nrm += w[k] * pd.target_normals[k][v];
      }
      // Then linear blend skinning (section 3.7.3): the skinned mesh node's own transform is ignored.
      glm::mat4 xf;
      if (skinned) {
        xf = glm::mat4(0.0f);
        const std::uint16_t* jv = &pd.joints[v * influences];
        const float* wv = &pd.weights[v * influences];
        for (std::size_t c = 0; c < influences; ++c) {
          if (wv[c] != 0.0f) xf += wv[c] * joints[jv[c]];
        }
      } else {
        xf = inst.model;
      }
      inst.world_positions[v] = glm::vec3(xf * glm::vec4(p, 1.0f));
      inst.world_normals[v] = safe_normalize(transform_normal(xf, nrm));
    }
    if (pd.flat_normals) {
      // Generated flat normals follow the deformed triangles.
      for (std::size_t t = 0; t + 2 < nv; t += 3) {
        const glm::vec3 nn = safe_normalize(glm::cross(inst.world_positions[t + 1] - inst.world_positions[t],
                                                       inst.world_positions[t + 2] - inst.world_positions[t]));
        inst.world_normals[t] = inst.world_normals[t + 1] = inst.world_normals[t + 2] = nn;
      }
    }
  }

  // Camera.
  CameraState& cam = out.camera;
  if (m.camera_node >= 0) {
    // The camera looks down its node's -Z; scale in the node's transform is removed (section 3.10).
    const glm::mat4& wm = world[static_cast<std::size_t>(m.camera_node)];
    glm::mat4 rigid(1.0f);
    rigid[0] = glm::vec4(safe_normalize(glm::vec3(wm[0])), 0.0f);
    rigid[1] = glm::vec4(safe_normalize(glm::vec3(wm[1])), 0.0f);
    rigid[2] = glm::vec4(safe_normalize(glm::vec3(wm[2])), 0.0f);
    rigid[3] = wm[3];
    cam.view = glm::inverse(rigid);
    cam.yfov = m.camera.yfov;
    cam.aspect = m.camera.aspect;
    cam.znear = m.camera.znear;
    cam.zfar = m.camera.zfar;
    cam.name = m.camera.name;
  } else {
    const double phase = 2.0 * 3.14159265358979323846 * time_s / m.path_period_s;
    glm::vec3 dir = m.auto_direction;
    float dist = m.auto_distance;
    if (m.path == CameraOptions::Path::Orbit) {
      const float a = static_cast<float>(phase);
      dir = glm::vec3(std::cos(a) * dir.x + std::sin(a) * dir.z, dir.y, -std::sin(a) * dir.x + std::cos(a) * dir.z);
      cam.name = "automatic (orbit)";
    } else if (m.path == CameraOptions::Path::Dolly) {
      dist *= static_cast<float>(1.0 - 0.35 * 0.5 * (1.0 - std::cos(phase)));
      cam.name = "automatic (dolly)";
    } else {
      cam.name = "automatic";
    }
    const glm::vec3 eye = m.auto_center + dir * dist;
    cam.view = glm::lookAt(eye, m.auto_center, glm::vec3(0.0f, 1.0f, 0.0f));
    cam.yfov = CameraState{}.yfov;
    cam.aspect = 0.0f;
    // The bounding sphere (radius = distance * sin(yfov / 2) / 1.05) stays between near and far on every path.
    const float radius = m.auto_distance * std::sin(0.5f * cam.yfov) / 1.05f;
    const float closest = 0.65f * m.auto_distance;
    cam.znear = std::max(0.5f * (closest - radius), 1e-3f * radius);
    cam.zfar = m.auto_distance + 2.0f * radius;
  }

  // Lights through their nodes: position = node origin, direction = node's -Z (KHR_lights_punctual).
  out.lights.clear();
  for (const scene_detail::LightDef& def : m.lights) {
    LightState l = def.light;
    const glm::mat4& wm = world[static_cast<std::size_t>(def.node)];
    l.position = glm::vec3(wm[3]);
    l.direction = safe_normalize(glm::vec3(wm * glm::vec4(0.0f, 0.0f, -1.0f, 0.0f)));
    out.lights.push_back(l);
  }
  if (out.lights.empty()) out.lights.push_back(m.key_light);
}

}  // namespace temporal
