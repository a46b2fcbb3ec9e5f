// Scene::load: tinygltf parses the file; everything a replay needs is converted here, once, into flat
// arrays (triangles, float keyframes, parents-first node order) and validated, so that evaluate() never
// meets a bad index.
#include "loader.h"

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <glm/gtx/matrix_decompose.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <numeric>
#include <set>

namespace temporal {
namespace scene_detail {

std::string quoted_or_index(const std::string& name, std::size_t index) {
  std::string s = name.empty() ? std::string("#") : std::string("'");
  s += name.empty() ? std::to_string(index) : name + "'";
  return s;
}

}  // namespace scene_detail

namespace {

using scene_detail::Impl;
using scene_detail::Loader;
using scene_detail::PrimitiveData;
using scene_detail::quoted_or_index;
using scene_detail::read_floats;

const std::set<std::string>& supported_required_extensions() {
  static const std::set<std::string> s = {"KHR_lights_punctual", "KHR_mesh_quantization",
                                          "KHR_materials_emissive_strength", "KHR_texture_transform"};
  return s;
}

std::string trim(std::string s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.pop_back();
  return s;
}

std::string one_line(std::string s) {
  s = trim(std::move(s));
  std::replace(s.begin(), s.end(), '\n', ';');
  return s;
}

bool is_index(const std::string& s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isdigit(c) != 0; });
}

std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : ", ") + x;
  return s.empty() ? "none" : s;
}

// Loader state shared by the helpers below.
}  // namespace

namespace scene_detail {

Status Loader::load_nodes_and_order(std::vector<char>& in_scene) {
  const std::size_t count = model.nodes.size();
  impl.nodes.resize(count);
  for (std::size_t i = 0; i < count; ++i) {
    const tinygltf::Node& src = model.nodes[i];
    scene_detail::Node& n = impl.nodes[i];
    n.name = src.name;
    auto check = [&](int v, std::size_t size, const char* kind) -> Status {
      if (v >= static_cast<int>(size)) {
        return Error::input(file, "node " + quoted_or_index(src.name, i) + " names " + kind + " " + std::to_string(v) +
                                      ", which does not exist");
      }
      return Status::ok();
    };
    if (Status s = check(src.mesh, model.meshes.size(), "mesh"); !s) return s;
    if (Status s = check(src.skin, model.skins.size(), "skin"); !s) return s;
    if (Status s = check(src.camera, model.cameras.size(), "camera"); !s) return s;
    n.mesh = src.mesh;
    n.skin = src.skin;
    n.camera = src.camera;
    auto light = src.extensions.find("KHR_lights_punctual");
    if (light != src.extensions.end() && light->second.IsObject() && light->second.Has("light")) {
      n.light = light->second.Get("light").GetNumberAsInt();
      if (Status s = check(n.light, model.lights.size(), "light"); !s) return s;
      if (n.light < 0) return Error::input(file, "node " + quoted_or_index(src.name, i) + " names light -1");
    }
    if (src.matrix.size() == 16) {
      n.matrix = glm::make_mat4(src.matrix.data());
      n.use_matrix = true;
    } else {
      if (src.translation.size() == 3) n.translation = glm::vec3(src.translation[0], src.translation[1], src.translation[2]);
      if (src.rotation.size() == 4) {
        n.rotation = glm::normalize(glm::quat(static_cast<float>(src.rotation[3]), static_cast<float>(src.rotation[0]),
                                              static_cast<float>(src.rotation[1]), static_cast<float>(src.rotation[2])));
      }
      if (src.scale.size() == 3) n.scale = glm::vec3(src.scale[0], src.scale[1], src.scale[2]);
    }
    for (int c : src.children) {
      if (c < 0 || c >= static_cast<int>(count)) {
        return Error::input(file, "node " + quoted_or_index(src.name, i) + " has child " + std::to_string(c) +
                                      ", which does not exist");
      }
      scene_detail::Node& child = impl.nodes[static_cast<std::size_t>(c)];
      if (child.parent >= 0 || static_cast<std::size_t>(c) == i) {
        return Error::input(file, "node " + std::to_string(c) + " has more than one parent (the node graph must be a forest)");
      }
      child.parent = static_cast<int>(i);
    }
  }
  // Parents-first order over every node (joints may sit outside the drawn scene), depth first from the roots.
  impl.order.clear();
  std::vector<char> visited(count, 0);
  for (std::size_t r = 0; r < count; ++r) {
    if (impl.nodes[r].parent >= 0) continue;
    std::vector<int> stack{static_cast<int>(r)};
    while (!stack.empty()) {
      const int v = stack.back();
      stack.pop_back();
      visited[static_cast<std::size_t>(v)] = 1;
      impl.order.push_back(v);
      const auto& ch = model.nodes[static_cast<std::size_t>(v)].children;
      for (auto it = ch.rbegin(); it != ch.rend(); ++it) stack.push_back(*it);
    }
  }
  if (impl.order.size() != count) {
    return Error::input(file, "the node hierarchy has a cycle (a node is its own ancestor)");
  }
  // The drawn scene: `scene`, else scene 0, else every root.
  in_scene.assign(count, 0);
  std::vector<int> roots;
  if (!model.scenes.empty()) {
    const int si = model.defaultScene >= 0 && model.defaultScene < static_cast<int>(model.scenes.size()) ? model.defaultScene : 0;
    roots = model.scenes[static_cast<std::size_t>(si)].nodes;
    for (int rnode : roots) {
      if (rnode < 0 || rnode >= static_cast<int>(count)) {
        return Error::input(file, "scene " + std::to_string(si) + " names node " + std::to_string(rnode) + ", which does not exist");
      }
    }
  } else {
    for (std::size_t r = 0; r < count; ++r) {
      if (impl.nodes[r].parent < 0) roots.push_back(static_cast<int>(r));
    }
  }
  std::vector<int> stack(roots.begin(), roots.end());
  while (!stack.empty()) {
    const int v = stack.back();
    stack.pop_back();
    if (in_scene[static_cast<std::size_t>(v)]) continue;
    in_scene[static_cast<std::size_t>(v)] = 1;
    for (int c : model.nodes[static_cast<std::size_t>(v)].children) stack.push_back(c);
  }
  return Status::ok();
}

Status Loader::load_skins() {
  for (std::size_t i = 0; i < model.skins.size(); ++i) {
    const tinygltf::Skin& src = model.skins[i];
    scene_detail::Skin skin;
    const std::string what = "skin " + quoted_or_index(src.name, i);
    for (int j : src.joints) {
      if (j < 0 || j >= static_cast<int>(model.nodes.size())) {
        return Error::input(file, what + " names joint node " + std::to_string(j) + ", which does not exist");
      }
      skin.joints.push_back(j);
    }
    skin.inverse_bind.assign(skin.joints.size(), glm::mat4(1.0f));
    if (src.inverseBindMatrices >= 0) {
      std::vector<float> f;
      if (Status s = read_floats(model, src.inverseBindMatrices, 16, file, "inverseBindMatrices of " + what, f); !s) return s;
      if (f.size() < 16 * skin.joints.size()) {
        return Error::input(file, "inverseBindMatrices of " + what + " has " + std::to_string(f.size() / 16) +
                                      " matrices for " + std::to_string(skin.joints.size()) + " joints");
      }
      for (std::size_t j = 0; j < skin.joints.size(); ++j) skin.inverse_bind[j] = glm::make_mat4(&f[16 * j]);
    }
    impl.skins.push_back(std::move(skin));
  }
  return Status::ok();
}

Status Loader::load_animations(const std::string& clip, double& duration) {
  for (std::size_t i = 0; i < model.animations.size(); ++i) {
    impl.clip_names.push_back(model.animations[i].name.empty() ? std::to_string(i) : model.animations[i].name);
  }
  duration = 0.0;
  if (model.animations.empty()) {
    if (!clip.empty() && clip != "all") {
      return Error{ErrorKind::Usage, file, "clip '" + clip + "' asked for, but the scene has no animation"};
    }
    return Status::ok();
  }
  std::vector<std::size_t> selected;
  if (clip.empty()) {
    selected.push_back(0);
  } else if (clip == "all") {
    for (std::size_t i = 0; i < model.animations.size(); ++i) selected.push_back(i);
  } else {
    for (std::size_t i = 0; i < model.animations.size(); ++i) {
      if (model.animations[i].name == clip) selected.push_back(i);
    }
    if (selected.empty() && is_index(clip) && std::stoul(clip) < model.animations.size()) selected.push_back(std::stoul(clip));
    if (selected.empty()) {
      return Error{ErrorKind::Usage, file, "no animation clip '" + clip + "' (have: " + join(impl.clip_names) +
                                               "; give a name, an index or 'all')"};
    }
  }
  std::vector<char> animated(impl.nodes.size(), 0);
  for (std::size_t ai : selected) {
    const tinygltf::Animation& anim = model.animations[ai];
    const std::string aname = "animation " + quoted_or_index(anim.name, ai);
    std::map<int, int> sampler_map;  // this animation's sampler -> impl.samplers
    for (std::size_t ci = 0; ci < anim.channels.size(); ++ci) {
      const tinygltf::AnimationChannel& ch = anim.channels[ci];
      const std::string what = "channel " + std::to_string(ci) + " of " + aname;
      if (ch.target_node < 0) continue;  // no target: ignored (section 3.11: e.g. extension targets)
      if (ch.target_node >= static_cast<int>(impl.nodes.size())) {
        return Error::input(file, what + " targets node " + std::to_string(ch.target_node) + ", which does not exist");
      }
      if (ch.sampler < 0 || ch.sampler >= static_cast<int>(anim.samplers.size())) {
        return Error::input(file, what + " names sampler " + std::to_string(ch.sampler) + ", which does not exist");
      }
      scene_detail::Channel out;
      out.node = ch.target_node;
      scene_detail::Node& node = impl.nodes[static_cast<std::size_t>(out.node)];
      int components = 0;
      if (ch.target_path == "translation") { out.path = scene_detail::TargetPath::Translation; components = 3; }
      else if (ch.target_path == "rotation") { out.path = scene_detail::TargetPath::Rotation; components = 4; }
      else if (ch.target_path == "scale") { out.path = scene_detail::TargetPath::Scale; components = 3; }
      else if (ch.target_path == "weights") {
        out.path = scene_detail::TargetPath::Weights;
        components = node.weight_count;
        if (components == 0) {
          impl.warnings.push_back(what + " animates morph weights of a node without morph targets: ignored");
          continue;
        }
      } else {
        impl.warnings.push_back(what + " animates '" + ch.target_path + "': ignored");
        continue;
      }
      animated[static_cast<std::size_t>(out.node)] = 1;
      auto known = sampler_map.find(ch.sampler);
      if (known != sampler_map.end() && impl.samplers[static_cast<std::size_t>(known->second)].components == components) {
        out.sampler = known->second;
        impl.channels.push_back(out);
        continue;
      }
      const tinygltf::AnimationSampler& src = anim.samplers[static_cast<std::size_t>(ch.sampler)];
      scene_detail::Sampler s;
      s.components = components;
      if (src.interpolation == "STEP") s.interpolation = scene_detail::Interpolation::Step;
      else if (src.interpolation == "CUBICSPLINE") s.interpolation = scene_detail::Interpolation::CubicSpline;
      else if (src.interpolation == "LINEAR" || src.interpolation.empty()) s.interpolation = scene_detail::Interpolation::Linear;
      else return Error::input(file, what + ": unknown interpolation '" + src.interpolation + "'");
      if (Status st = read_floats(model, src.input, 1, file, "input of " + what, s.times); !st) return st;
      if (s.times.empty()) {
        impl.warnings.push_back(what + ": its sampler has no keyframes: ignored");
        continue;
      }
      if (Status st = read_floats(model, src.output, 0, file, "output of " + what, s.values); !st) return st;
      for (std::size_t k = 0; k < s.times.size(); ++k) {
        if (!std::isfinite(s.times[k]) || (k > 0 && s.times[k] < s.times[k - 1])) {
          return Error::input(file, "input of " + what + ": key times must be finite and increasing");
        }
      }
      const std::size_t expect = s.times.size() * static_cast<std::size_t>(components) *
                                 (s.interpolation == scene_detail::Interpolation::CubicSpline ? 3u : 1u);
      if (s.values.size() != expect) {
        return Error::input(file, "output of " + what + " holds " + std::to_string(s.values.size()) + " values, expected " +
                                      std::to_string(expect) + " (" + std::to_string(s.times.size()) + " keys of " +
                                      std::to_string(components) + " for " + src.interpolation + ")");
      }
      if (!std::all_of(s.values.begin(), s.values.end(), [](float x) { return std::isfinite(x); })) {
        return Error::input(file, "output of " + what + " holds NaN or infinite values");
      }
      if (!s.times.empty()) duration = std::max(duration, static_cast<double>(s.times.back()));
      out.sampler = static_cast<int>(impl.samplers.size());
      sampler_map[ch.sampler] = out.sampler;
      impl.samplers.push_back(std::move(s));
      impl.channels.push_back(out);
    }
  }
  // An animated node that gave `matrix` (the spec forbids it): decomposed into T, R, S so the channels apply.
  for (std::size_t i = 0; i < impl.nodes.size(); ++i) {
    scene_detail::Node& n = impl.nodes[i];
    if (!animated[i] || !n.use_matrix) continue;
    glm::vec3 skew;
    glm::vec4 persp;
    glm::decompose(n.matrix, n.scale, n.rotation, n.translation, skew, persp);
    n.use_matrix = false;
    impl.warnings.push_back("node " + quoted_or_index(n.name, i) + " is animated but has a matrix: decomposed into TRS");
  }
  return Status::ok();
}

Status Loader::load_cameras_and_lights(const std::vector<char>& in_scene) {
  for (std::size_t i = 0; i < model.cameras.size(); ++i) {
    const tinygltf::Camera& c = model.cameras[i];
    scene_detail::CameraDef def;
    def.name = c.name.empty() ? std::to_string(i) : c.name;
    if (c.type == "orthographic") {
      def.orthographic = true;
    } else {
      def.yfov = static_cast<float>(c.perspective.yfov);
      def.aspect = static_cast<float>(c.perspective.aspectRatio);
      def.znear = static_cast<float>(c.perspective.znear);
      def.zfar = static_cast<float>(c.perspective.zfar);
      if (!(def.yfov > 0.0f && def.yfov < 3.14f) || !(def.znear > 0.0f) || (def.zfar != 0.0f && !(def.zfar > def.znear))) {
        return Error::input(file, "camera " + quoted_or_index(c.name, i) + " has an invalid yfov, znear or zfar");
      }
    }
    impl.cameras.push_back(def);
  }
  for (int v : impl.order) {
    const scene_detail::Node& n = impl.nodes[static_cast<std::size_t>(v)];
    if (!in_scene[static_cast<std::size_t>(v)] || n.light < 0) continue;
    const tinygltf::Light& src = model.lights[static_cast<std::size_t>(n.light)];
    scene_detail::LightDef def;
    def.node = v;
    if (src.type == "directional") def.light.type = LightState::Type::Directional;
    else if (src.type == "point") def.light.type = LightState::Type::Point;
    else if (src.type == "spot") def.light.type = LightState::Type::Spot;
    else {
      impl.warnings.push_back("light " + std::to_string(n.light) + " has unknown type '" + src.type + "': ignored");
      continue;
    }
    if (src.color.size() == 3) def.light.color = glm::vec3(src.color[0], src.color[1], src.color[2]);
    def.light.intensity = static_cast<float>(src.intensity);
    def.light.range = static_cast<float>(src.range);
    def.light.inner_cone = static_cast<float>(src.spot.innerConeAngle);
    def.light.outer_cone = static_cast<float>(src.spot.outerConeAngle);
    impl.lights.push_back(def);
  }
  return Status::ok();
}
}  // namespace scene_detail

Expected<Scene> Scene::load(const std::string& path, const SceneLoadOptions& options) {
  // The loader validates before it reads; the guard turns what is left (an allocation that a corrupt but
  // in-bounds file can still ask for) into an Input error instead of a crash.
  try {
    return load_checked(path, options);
  } catch (const std::exception& e) {
    return Error::input(path, std::string("cannot load the scene: ") + e.what());
  }
}

Expected<Scene> Scene::load_checked(const std::string& path, const SceneLoadOptions& options) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) {
    return Error::input(path, "no such file (give a .gltf or .glb scene)");
  }
  // .glb is recognised by its magic, whatever the extension says.
  bool binary = false;
  {
    std::ifstream in(path, std::ios::binary);
    char magic[4] = {};
    in.read(magic, 4);
    binary = in.gcount() == 4 && std::string(magic, 4) == "glTF";
  }
  tinygltf::TinyGLTF gltf;
  tinygltf::Model model;
  std::string err, warn;
  bool ok = false;
  try {
    ok = binary ? gltf.LoadBinaryFromFile(&model, &err, &warn, path) : gltf.LoadASCIIFromFile(&model, &err, &warn, path);
  } catch (const std::exception& e) {
    err = e.what();
  }
  if (!ok) {
    if (err.empty()) err = warn;
    return Error::input(path, "not a valid glTF 2.0 file: " + one_line(err));
  }
  for (const std::string& ext : model.extensionsRequired) {
    if (!supported_required_extensions().count(ext)) {
      return Error::input(path, "the scene requires the glTF extension " + ext +
                                    ", which is not supported (supported: KHR_lights_punctual, KHR_mesh_quantization, "
                                    "KHR_materials_emissive_strength, KHR_texture_transform); export the scene without it");
    }
  }

  Scene scene;
  Impl& impl = *scene.impl_;
  impl.file = path;
  if (!warn.empty()) impl.warnings.push_back(one_line(warn));
  Loader ld{model, path, impl, scene.primitives_, scene.materials_, scene.textures_, {}, {}, {}, {}, {}, -1};

  std::vector<char> in_scene;
  if (Status s = ld.load_nodes_and_order(in_scene); !s) return s.error();
  if (Status s = ld.load_materials(); !s) return s.error();

  // Meshes drawn by the scene's nodes (each loaded once, however many nodes draw it).
  ld.mesh_primitives.assign(model.meshes.size(), {});
  ld.mesh_targets.assign(model.meshes.size(), 0);
  std::vector<char> mesh_loaded(model.meshes.size(), 0), mesh_skinned(model.meshes.size(), 0);
  for (std::size_t v = 0; v < impl.nodes.size(); ++v) {
    if (in_scene[v] && impl.nodes[v].mesh >= 0 && impl.nodes[v].skin >= 0) mesh_skinned[static_cast<std::size_t>(impl.nodes[v].mesh)] = 1;
  }
  for (int v : impl.order) {
    const int mesh = impl.nodes[static_cast<std::size_t>(v)].mesh;
    if (!in_scene[static_cast<std::size_t>(v)] || mesh < 0 || mesh_loaded[static_cast<std::size_t>(mesh)]) continue;
    mesh_loaded[static_cast<std::size_t>(mesh)] = 1;
    if (Status s = ld.load_mesh(mesh, mesh_skinned[static_cast<std::size_t>(mesh)] != 0); !s) return s.error();
  }
  if (Status s = ld.load_skins(); !s) return s.error();

  // Draw list and morph weight slots, in node order (stable, so evaluations pair index by index).
  for (int v : impl.order) {
    scene_detail::Node& n = impl.nodes[static_cast<std::size_t>(v)];
    if (!in_scene[static_cast<std::size_t>(v)] || n.mesh < 0) continue;
    const tinygltf::Mesh& mesh = model.meshes[static_cast<std::size_t>(n.mesh)];
    const int targets = ld.mesh_targets[static_cast<std::size_t>(n.mesh)];
    if (targets > 0) {
      n.weight_offset = impl.weight_total;
      n.weight_count = targets;
      impl.weight_total += targets;
      const auto& src = model.nodes[static_cast<std::size_t>(v)].weights.size() == static_cast<std::size_t>(targets)
                            ? model.nodes[static_cast<std::size_t>(v)].weights
                            : mesh.weights;
      n.rest_weights.assign(static_cast<std::size_t>(targets), 0.0f);
      if (src.size() == static_cast<std::size_t>(targets)) {
        for (int k = 0; k < targets; ++k) n.rest_weights[static_cast<std::size_t>(k)] = static_cast<float>(src[static_cast<std::size_t>(k)]);
      }
    }
    for (int p : ld.mesh_primitives[static_cast<std::size_t>(n.mesh)]) {
      if (p < 0) continue;
      if (n.skin >= 0 && impl.primitive_data[static_cast<std::size_t>(p)].influences > 0 &&
          ld.max_joint[static_cast<std::size_t>(p)] > impl.skins[static_cast<std::size_t>(n.skin)].joints.size()) {
        return Error::input(path, "mesh " + quoted_or_index(mesh.name, static_cast<std::size_t>(n.mesh)) +
                                      " uses joint " + std::to_string(ld.max_joint[static_cast<std::size_t>(p)] - 1) +
                                      " but skin " + std::to_string(n.skin) + " has only " +
                                      std::to_string(impl.skins[static_cast<std::size_t>(n.skin)].joints.size()) + " joints");
      }
      impl.draws.push_back({v, p});
    }
  }
  if (impl.draws.empty()) {
    return Error::input(path, "the scene has no triangles to draw (no mesh with a triangle primitive in its node tree)");
  }

  if (Status s = ld.load_animations(options.clip, scene.clip_duration_); !s) return s.error();
  if (Status s = ld.load_cameras_and_lights(in_scene); !s) return s.error();

  // Bounds at t = 0 (skinned and morphed meshes in their pose at t = 0).
  FrameState f0;
  scene.evaluate(0.0, f0);
  glm::vec3 lo(std::numeric_limits<float>::max()), hi(std::numeric_limits<float>::lowest());
  for (const PrimitiveInstance& inst : f0.instances) {
    if (inst.deformed) {
      for (const auto& p : inst.world_positions) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
      }
    } else {
      const PrimitiveData& d = impl.primitive_data[static_cast<std::size_t>(inst.primitive)];
      for (int c = 0; c < 8; ++c) {
        const glm::vec3 corner((c & 1) ? d.local_max.x : d.local_min.x, (c & 2) ? d.local_max.y : d.local_min.y,
                               (c & 4) ? d.local_max.z : d.local_min.z);
        const glm::vec3 w = glm::vec3(inst.model * glm::vec4(corner, 1.0f));
        lo = glm::min(lo, w);
        hi = glm::max(hi, w);
      }
    }
  }
  scene.bounds_min_ = lo;
  scene.bounds_max_ = hi;
  const glm::vec3 center = 0.5f * (lo + hi);
  const float radius = std::max(0.5f * glm::length(hi - lo), 1e-3f);

  // Camera: the named / first perspective glTF camera through its node, or the automatic one.
  const CameraOptions& co = options.camera;
  impl.path = co.path;
  impl.path_period_s = co.path_period_s > 0.0 ? co.path_period_s : 8.0;
  int camera_index = -1;
  if (!co.camera.empty()) {
    for (std::size_t i = 0; i < impl.cameras.size(); ++i) {
      if (model.cameras[i].name == co.camera) camera_index = static_cast<int>(i);
    }
    if (camera_index < 0 && is_index(co.camera) && std::stoul(co.camera) < impl.cameras.size()) camera_index = std::stoi(co.camera);
    if (camera_index < 0) {
      return Error{ErrorKind::Usage, path, "no camera '" + co.camera + "' (have: " + join(scene.camera_names()) +
                                               "); give a name or an index, or omit it for the automatic camera"};
    }
    if (impl.cameras[static_cast<std::size_t>(camera_index)].orthographic) {
      return Error{ErrorKind::Usage, path, "camera '" + co.camera + "' is orthographic, which is not supported (only "
                                               "perspective cameras); choose another camera or the automatic one"};
    }
  }
  if (co.path == CameraOptions::Path::Fixed) {
    for (int v : impl.order) {
      const int c = impl.nodes[static_cast<std::size_t>(v)].camera;
      if (!in_scene[static_cast<std::size_t>(v)] || c < 0) continue;
      if (camera_index >= 0 ? c == camera_index : !impl.cameras[static_cast<std::size_t>(c)].orthographic) {
        impl.camera_node = v;
        impl.camera = impl.cameras[static_cast<std::size_t>(c)];
        break;
      }
    }
    if (camera_index >= 0 && impl.camera_node < 0) {
      return Error{ErrorKind::Usage, path, "camera '" + co.camera + "' is not attached to any node of the scene"};
    }
  }
  // Automatic camera: frames the bounding sphere from the front (+Z), a little from the right and above.
  impl.auto_center = center;
  impl.auto_direction = glm::normalize(glm::vec3(0.45f, 0.35f, 1.0f));
  const float auto_yfov = CameraState{}.yfov;
  impl.auto_distance = radius / std::sin(0.5f * auto_yfov) * 1.05f;
  if (impl.camera_node >= 0) {
    if (impl.camera.zfar == 0.0f) {
      // Infinite projection in the file: a far plane beyond the whole scene as seen from the camera at t = 0.
      const glm::vec3 eye(glm::inverse(scene.evaluate(0.0).camera.view)[3]);
      impl.camera.zfar = std::max(2.0f * (glm::length(eye - center) + radius), 2.0f * impl.camera.znear);
    }
  }
  // Key light when the scene has none: a white directional light from above, behind the camera's left
  // shoulder at t = 0; intensity pi, so a white Lambertian surface facing it reflects radiance 1.
  if (impl.lights.empty()) {
    const glm::mat4 cam_to_world = glm::inverse(scene.evaluate(0.0).camera.view);
    const glm::vec3 right(cam_to_world[0]), up(cam_to_world[1]), back(cam_to_world[2]);
    impl.key_light.type = LightState::Type::Directional;
    impl.key_light.direction = glm::normalize(-back * 1.0f - up * 1.2f + right * 0.6f);
    impl.key_light.color = glm::vec3(1.0f);
    impl.key_light.intensity = 3.14159265f;
  }
  return scene;
}

}  // namespace temporal
