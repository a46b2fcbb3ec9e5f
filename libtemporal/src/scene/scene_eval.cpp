// Scene::evaluate: channels and time samples -> local transforms -> world matrices (parents first) -> rigid
// instances (a model matrix) or deformed ones (point caches, morph targets / blend shapes, then linear blend
// skinning, on the CPU). Format-neutral: it sees only the SceneDescription.
#include "scene_description.h"

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>

namespace temporal {

using scene_detail::Impl;
using scene_detail::PrimitiveData;

Scene::Scene() : impl_(std::make_unique<Impl>()) {}
Scene::Scene(Scene&&) noexcept = default;
Scene& Scene::operator=(Scene&&) noexcept = default;
Scene::~Scene() = default;

const std::vector<ScenePrimitive>& Scene::primitives() const { return impl_->primitives; }
const std::vector<SceneMaterial>& Scene::materials() const { return impl_->materials; }
const std::vector<SceneTexture>& Scene::textures() const { return impl_->textures; }
glm::vec3 Scene::bounds_min() const { return impl_->bounds_min; }
glm::vec3 Scene::bounds_max() const { return impl_->bounds_max; }
double Scene::clip_duration() const { return impl_->clip_duration; }
std::vector<std::string> Scene::clip_names() const { return impl_->clip_names; }
const std::string& Scene::format() const { return impl_->format; }
glm::vec3 Scene::ambient() const { return impl_->ambient; }

std::vector<std::string> Scene::camera_names() const {
  std::vector<std::string> names;
  for (const auto& c : impl_->cameras) names.push_back(c.name + (c.orthographic ? " (orthographic)" : ""));
  return names;
}

const std::vector<std::string>& Scene::warnings() const { return impl_->warnings; }
const std::vector<std::string>& Scene::input_files() const { return impl_->inputs; }
const std::string& Scene::file() const { return impl_->file; }

FrameRange Scene::default_frames(double fps, double duration_s) const {
  double seconds = duration_s;
  if (seconds <= 0.0) seconds = clip_duration();
  if (seconds <= 0.0 && impl_->path != CameraOptions::Path::Fixed) seconds = impl_->path_period_s;
  FrameRange r;
  r.last = seconds > 0.0 ? std::max(0, int(std::ceil(seconds * fps - 1e-9)) - 1) : 0;
  return r;
}

Expected<CameraOptions::Path> parse_camera_path(const std::string& text) {
  if (text == "fixed") return CameraOptions::Path::Fixed;
  if (text == "orbit") return CameraOptions::Path::Orbit;
  if (text == "dolly") return CameraOptions::Path::Dolly;
  return Error::usage("--camera-path '" + text + "': use fixed, orbit or dolly");
}

const char* camera_path_name(CameraOptions::Path path) {
  switch (path) {
    case CameraOptions::Path::Orbit: return "orbit";
    case CameraOptions::Path::Dolly: return "dolly";
    case CameraOptions::Path::Fixed: break;
  }
  return "fixed";
}

FrameState Scene::evaluate(double time_s) const {
  FrameState f;
  evaluate(time_s, f);
  return f;
}

namespace {

constexpr float kDegrees = 0.017453292519943295f;

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

glm::mat4 rotation(int axis, float degrees) {
  glm::vec3 a(0.0f);
  a[axis] = 1.0f;
  return glm::rotate(glm::mat4(1.0f), degrees * kDegrees, a);
}

// The matrix of one USD transform op with value v (UsdGeomXformOp: rotateXYZ turns about X first, so its
// matrix is Rz * Ry * Rx for column vectors; the other orders likewise).
glm::mat4 op_matrix(const scene_detail::XformOp& op, const float* v) {
  using K = scene_detail::XformOp::Kind;
  glm::mat4 m(1.0f);
  auto euler = [&](int first, int second, int third) {
    return rotation(third, v[third]) * rotation(second, v[second]) * rotation(first, v[first]);
  };
  switch (op.kind) {
    case K::Translate: m = glm::translate(glm::mat4(1.0f), glm::vec3(v[0], v[1], v[2])); break;
    case K::Scale: m = glm::scale(glm::mat4(1.0f), glm::vec3(v[0], v[1], v[2])); break;
    case K::RotateX: m = rotation(0, v[0]); break;
    case K::RotateY: m = rotation(1, v[0]); break;
    case K::RotateZ: m = rotation(2, v[0]); break;
    case K::RotateXYZ: m = euler(0, 1, 2); break;
    case K::RotateXZY: m = euler(0, 2, 1); break;
    case K::RotateYXZ: m = euler(1, 0, 2); break;
    case K::RotateYZX: m = euler(1, 2, 0); break;
    case K::RotateZXY: m = euler(2, 0, 1); break;
    case K::RotateZYX: m = euler(2, 1, 0); break;
    case K::Orient: m = glm::mat4_cast(glm::normalize(glm::quat(v[3], v[0], v[1], v[2]))); break;
    case K::Transform: m = glm::make_mat4(v); break;
  }
  return op.inverse ? glm::inverse(m) : m;
}

// Local transforms of every node at animation time ta, and the morph weights of every weight slot.
struct LocalState {
  std::vector<glm::vec3> translation, scale;
  std::vector<glm::quat> rotation;
  std::vector<float> weights;
};

void animate_nodes(const Impl& m, float ta, LocalState& s) {
  const std::size_t n_nodes = m.nodes.size();
  s.translation.resize(n_nodes);
  s.scale.resize(n_nodes);
  s.rotation.resize(n_nodes);
  s.weights.assign(static_cast<std::size_t>(m.weight_total), 0.0f);
  for (std::size_t i = 0; i < n_nodes; ++i) {
    const scene_detail::Node& n = m.nodes[i];
    s.translation[i] = n.translation;
    s.rotation[i] = n.rotation;
    s.scale[i] = n.scale;
    if (n.weight_count > 0) std::copy(n.rest_weights.begin(), n.rest_weights.end(), s.weights.begin() + n.weight_offset);
  }
  float value[4];
  std::vector<float> wide;
  for (const scene_detail::Channel& ch : m.channels) {
    const scene_detail::Sampler& smp = m.samplers[static_cast<std::size_t>(ch.sampler)];
    const auto node = static_cast<std::size_t>(ch.node);
    switch (ch.path) {
      case scene_detail::TargetPath::Translation:
        scene_detail::sample(smp, ta, false, value);
        s.translation[node] = glm::vec3(value[0], value[1], value[2]);
        break;
      case scene_detail::TargetPath::Scale:
        scene_detail::sample(smp, ta, false, value);
        s.scale[node] = glm::vec3(value[0], value[1], value[2]);
        break;
      case scene_detail::TargetPath::Rotation:
        scene_detail::sample(smp, ta, true, value);
        s.rotation[node] = glm::quat(value[3], value[0], value[1], value[2]);  // stored x, y, z, w
        break;
      case scene_detail::TargetPath::Weights:
        wide.resize(static_cast<std::size_t>(smp.components));
        scene_detail::sample(smp, ta, false, wide.data());
        std::copy(wide.begin(), wide.end(), s.weights.begin() + m.nodes[node].weight_offset);
        break;
    }
  }
}

glm::mat4 ops_local(const Impl& m, const scene_detail::Node& n, float ta) {
  glm::mat4 local(1.0f);
  float value[16];
  for (const scene_detail::XformOp& op : n.ops) {
    const float* v = op.value.data();
    if (op.sampler >= 0) {
      scene_detail::sample(m.samplers[static_cast<std::size_t>(op.sampler)], ta,
                           op.kind == scene_detail::XformOp::Kind::Orient, value);
      v = value;
    }
    local = local * op_matrix(op, v);
  }
  return local;
}

// World matrices, parents first.
void world_matrices(const Impl& m, const LocalState& s, float ta, std::vector<glm::mat4>& world) {
  world.resize(m.nodes.size());
  for (int v : m.order) {
    const auto i = static_cast<std::size_t>(v);
    const scene_detail::Node& n = m.nodes[i];
    const glm::mat4 local = !n.ops.empty() ? ops_local(m, n, ta)
                            : n.use_matrix ? n.matrix
                                           : compose(s.translation[i], s.rotation[i], s.scale[i]);
    world[i] = n.parent >= 0 && !n.reset_parent ? world[static_cast<std::size_t>(n.parent)] * local : local;
  }
}

// Smooth normals of deformed vertices: area-weighted face normals summed per point (vertex_point) and
// normalised, for meshes whose normals were generated smooth (USD meshes without normals).
void smooth_normals(const ScenePrimitive& prim, const PrimitiveData& pd, PrimitiveInstance& inst,
                    std::vector<glm::vec3>& scratch) {
  const std::size_t nv = inst.world_positions.size();
  auto point = [&](std::size_t v) { return pd.vertex_point.empty() ? v : std::size_t(pd.vertex_point[v]); };
  std::size_t points = 0;
  for (std::size_t v = 0; v < nv; ++v) points = std::max(points, point(v) + 1);
  scratch.assign(points, glm::vec3(0.0f));
  for (std::size_t t = 0; t + 2 < prim.indices.size(); t += 3) {
    const std::uint32_t a = prim.indices[t], b = prim.indices[t + 1], c = prim.indices[t + 2];
    const glm::vec3 n = glm::cross(inst.world_positions[b] - inst.world_positions[a],
                                   inst.world_positions[c] - inst.world_positions[a]);
    scratch[point(a)] += n;
    scratch[point(b)] += n;
    scratch[point(c)] += n;
  }
  for (std::size_t v = 0; v < nv; ++v) inst.world_normals[v] = safe_normalize(scratch[point(v)]);
}

struct DeformInput {
  const float* weights = nullptr;    // morph weights of the node, nullptr: not morphed
  std::size_t n_targets = 0;
  const glm::mat4* joints = nullptr;  // joint matrices of the node's skin, nullptr: not skinned
  const glm::mat3* joint_normals = nullptr;  // their inverse transposes when the skin blends those (UsdSkel)
  const float* points = nullptr;      // sampled points (3 per point), nullptr: rest positions
  const float* point_normals = nullptr;
};

void deform(const ScenePrimitive& prim, const PrimitiveData& pd, const DeformInput& in, PrimitiveInstance& inst,
            std::vector<glm::vec3>& scratch) {
  const std::size_t nv = prim.positions.size();
  inst.world_positions.resize(nv);
  inst.world_normals.resize(nv);
  const auto influences = static_cast<std::size_t>(pd.influences);
  for (std::size_t v = 0; v < nv; ++v) {
    const std::size_t pt = pd.vertex_point.empty() ? v : pd.vertex_point[v];
    const std::size_t ne = pd.vertex_normal.empty() ? pt : pd.vertex_normal[v];
    glm::vec3 p = in.points ? glm::make_vec3(in.points + 3 * pt) : prim.positions[v];
    glm::vec3 nrm = in.point_normals ? glm::make_vec3(in.point_normals + 3 * ne) : prim.normals[v];
    // Morph targets first (glTF section 3.7.2.2; UsdSkel applies blend shapes before skinning too).
    for (std::size_t k = 0; k < in.n_targets; ++k) {
      if (in.weights[k] == 0.0f) continue;
      p += in.weights[k] * pd.target_positions[k][v];
      if (!pd.target_normals[k].empty()) nrm += in.weights[k] * pd.target_normals[k][v];
    }
    // Then linear blend skinning (section 3.7.3): the skinned mesh node's own transform is ignored.
    glm::mat4 xf;
    if (in.joints) {
      xf = glm::mat4(0.0f);
      const std::uint16_t* jv = &pd.joints[v * influences];
      const float* wv = &pd.weights[v * influences];
      for (std::size_t c = 0; c < influences; ++c) {
        if (wv[c] != 0.0f) xf += wv[c] * in.joints[jv[c]];
      }
    } else {
      xf = inst.model;
    }
    inst.world_positions[v] = glm::vec3(xf * glm::vec4(p, 1.0f));
    if (in.joint_normals) {
      glm::vec3 n(0.0f);
      const std::uint16_t* jv = &pd.joints[v * influences];
      const float* wv = &pd.weights[v * influences];
      for (std::size_t c = 0; c < influences; ++c) {
        if (wv[c] != 0.0f) n += wv[c] * (in.joint_normals[jv[c]] * nrm);
      }
      inst.world_normals[v] = safe_normalize(n);
    } else {
      inst.world_normals[v] = safe_normalize(transform_normal(xf, nrm));
    }
  }
  if (pd.flat_normals) {
    // Generated flat normals follow the deformed triangles.
    for (std::size_t t = 0; t + 2 < nv; t += 3) {
      const glm::vec3 nn = safe_normalize(glm::cross(inst.world_positions[t + 1] - inst.world_positions[t],
                                                     inst.world_positions[t + 2] - inst.world_positions[t]));
      inst.world_normals[t] = inst.world_normals[t + 1] = inst.world_normals[t + 2] = nn;
    }
  } else if (pd.smooth_normals) {
    smooth_normals(prim, pd, inst, scratch);  // generated smooth: recomputed from the deformed triangles
  }
}

void camera_state(const Impl& m, const std::vector<glm::mat4>& world, double time_s, float ta, CameraState& cam) {
  if (m.camera_instance >= 0) {
    // The camera looks down its node's -Z; scale in the node's transform is removed (glTF section 3.10).
    const glm::mat4& wm = world[static_cast<std::size_t>(m.camera_instances[static_cast<std::size_t>(m.camera_instance)].node)];
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
    if (m.camera.focal_sampler >= 0 || m.camera.aperture_sampler >= 0) {
      float focal = m.camera.focal_length, aperture = m.camera.vertical_aperture;
      if (m.camera.focal_sampler >= 0) scene_detail::sample(m.samplers[std::size_t(m.camera.focal_sampler)], ta, false, &focal);
      if (m.camera.aperture_sampler >= 0) scene_detail::sample(m.samplers[std::size_t(m.camera.aperture_sampler)], ta, false, &aperture);
      if (focal > 0.0f && aperture > 0.0f) cam.yfov = 2.0f * std::atan(0.5f * aperture / focal);
    }
    if (m.camera.clipping_sampler >= 0) {
      float range[2];
      scene_detail::sample(m.samplers[std::size_t(m.camera.clipping_sampler)], ta, false, range);
      if (range[0] > 0.0f && range[1] > range[0]) {
        cam.znear = range[0];
        cam.zfar = range[1];
      }
    }
    return;
  }
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

}  // namespace

void Scene::evaluate(double time_s, FrameState& out) const {
  const Impl& m = *impl_;
  out.time = time_s;
  // Animation time wraps at the clip's end so sequences may run longer than the clip.
  double wrapped = time_s;
  if (m.clip_duration > 0.0) {
    wrapped = std::fmod(time_s, m.clip_duration);
    if (wrapped < 0.0) wrapped += m.clip_duration;
  }
  const auto ta = static_cast<float>(wrapped);

  LocalState local;
  animate_nodes(m, ta, local);
  std::vector<glm::mat4> world;
  world_matrices(m, local, ta, world);

  // Joint matrices of every skin (glTF section 3.7.3.1): world(joint) * inverseBind(joint); for skins that
  // blend normal matrices, their inverse transposes too.
  std::vector<std::vector<glm::mat4>> joint_matrices(m.skins.size());
  std::vector<std::vector<glm::mat3>> joint_normals(m.skins.size());
  for (std::size_t s = 0; s < m.skins.size(); ++s) {
    const scene_detail::Skin& skin = m.skins[s];
    joint_matrices[s].resize(skin.joints.size());
    for (std::size_t j = 0; j < skin.joints.size(); ++j) {
      joint_matrices[s][j] = world[static_cast<std::size_t>(skin.joints[j])] * skin.inverse_bind[j];
    }
    if (!skin.blend_normal_matrices) continue;
    joint_normals[s].resize(skin.joints.size());
    for (std::size_t j = 0; j < skin.joints.size(); ++j)
      joint_normals[s][j] = glm::transpose(glm::inverse(glm::mat3(joint_matrices[s][j])));
  }

  std::vector<float> points, point_normals;
  std::vector<glm::vec3> scratch;
  out.instances.resize(m.draws.size());
  for (std::size_t d = 0; d < m.draws.size(); ++d) {
    const scene_detail::Draw& draw = m.draws[d];
    const scene_detail::Node& node = m.nodes[static_cast<std::size_t>(draw.node)];
    const ScenePrimitive& prim = m.primitives[static_cast<std::size_t>(draw.primitive)];
    const PrimitiveData& pd = m.primitive_data[static_cast<std::size_t>(draw.primitive)];
    PrimitiveInstance& inst = out.instances[d];
    inst.primitive = draw.primitive;
    inst.node = draw.node;
    inst.id = static_cast<std::uint32_t>(prim.material + 1);
    inst.model = world[static_cast<std::size_t>(draw.node)];
    const bool skinned = node.skin >= 0 && pd.influences > 0;
    const bool morphed = !pd.target_positions.empty() && node.weight_count > 0;
    const bool cached = pd.point_sampler >= 0;
    inst.deformed = skinned || morphed || cached;
    if (!inst.deformed) {
      inst.world_positions.clear();
      inst.world_normals.clear();
      continue;
    }
    DeformInput in;
    if (morphed) {
      in.weights = local.weights.data() + node.weight_offset;
      in.n_targets = std::min(pd.target_positions.size(), static_cast<std::size_t>(node.weight_count));
    }
    if (skinned) {
      in.joints = joint_matrices[static_cast<std::size_t>(node.skin)].data();
      if (!joint_normals[static_cast<std::size_t>(node.skin)].empty()) in.joint_normals = joint_normals[static_cast<std::size_t>(node.skin)].data();
    }
    if (cached) {
      const scene_detail::Sampler& s = m.samplers[static_cast<std::size_t>(pd.point_sampler)];
      points.resize(static_cast<std::size_t>(s.components));
      scene_detail::sample(s, ta, false, points.data());
      in.points = points.data();
      if (pd.normal_sampler >= 0) {
        const scene_detail::Sampler& sn = m.samplers[static_cast<std::size_t>(pd.normal_sampler)];
        point_normals.resize(static_cast<std::size_t>(sn.components));
        scene_detail::sample(sn, ta, false, point_normals.data());
        in.point_normals = point_normals.data();
      }
    }
    deform(prim, pd, in, inst, scratch);
  }

  camera_state(m, world, time_s, ta, out.camera);

  // Lights through their nodes: position = node origin, direction = node's -Z (KHR_lights_punctual, UsdLux).
  out.lights.clear();
  for (const scene_detail::LightDef& def : m.lights) {
    LightState l = def.light;
    const glm::mat4& wm = world[static_cast<std::size_t>(def.node)];
    l.position = glm::vec3(wm[3]);
    l.direction = safe_normalize(glm::vec3(wm * glm::vec4(0.0f, 0.0f, -1.0f, 0.0f)));
    out.lights.push_back(l);
  }
  if (out.lights.empty()) out.lights.push_back(m.key_light);
  out.ambient = m.ambient;
}

}  // namespace temporal
