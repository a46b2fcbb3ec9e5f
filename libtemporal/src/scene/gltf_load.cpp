// glTF 2.0 reader: tinygltf parses the file; everything a replay needs is converted here, once, into the
// format-neutral SceneDescription (flat arrays, float keyframes, parents-first node order) and validated, so
// that evaluate() never meets a bad index. Meshes and materials: gltf_mesh.cpp.
#include "gltf_reader.h"

#include <glm/gtc/type_ptr.hpp>
#include <glm/gtx/matrix_decompose.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <string_view>

namespace temporal::scene_detail {

std::string quoted_or_index(const std::string& name, std::size_t index) {
  std::string s = name.empty() ? std::string("#") : std::string("'");
  s += name.empty() ? std::to_string(index) : name + "'";
  return s;
}

bool is_index(const std::string& s) {
  return !s.empty() && s.size() <= 9 &&
         std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isdigit(c) != 0; });
}

std::string join_names(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& x : names) s += (s.empty() ? "" : ", ") + x;
  return s.empty() ? "none" : s;
}

namespace {

const std::set<std::string>& supported_required_extensions() {
  static const std::set<std::string> s = {"KHR_lights_punctual", "KHR_mesh_quantization",
                                          "KHR_materials_emissive_strength", "KHR_texture_transform"};
  return s;
}

std::string one_line(std::string s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.pop_back();
  std::replace(s.begin(), s.end(), '\n', ';');
  return s;
}

// JSON nesting deeper than this is refused before tinygltf parses it: its JSON-to-Value conversion recurses once
// per level, so 20 000 nested arrays in `extras` overflowed the stack (issue 26). Real glTF files nest a few
// levels (extras included); 256 leaves room for any exporter's metadata.
constexpr int kMaxJsonDepth = 256;

// The deepest nesting of [ and { in `json` (outside strings), counting up to kMaxJsonDepth + 1; the byte offset
// where the limit was passed in `where`.
int json_depth(std::string_view json, std::size_t* where) {
  int depth = 0, deepest = 0;
  bool in_string = false, escaped = false;
  for (std::size_t i = 0; i < json.size(); ++i) {
    const char c = json[i];
    if (in_string) {
      if (escaped) escaped = false;
      else if (c == '\\') escaped = true;
      else if (c == '"') in_string = false;
      continue;
    }
    if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      deepest = std::max(deepest, ++depth);
      if (depth > kMaxJsonDepth) {
        *where = i;
        return depth;
      }
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return deepest;
}

// The JSON text of a .gltf file, or the JSON chunk of a .glb (empty when the file cannot be read: tinygltf says why).
std::string json_text(const std::string& path, bool binary) {
  std::ifstream in(path, std::ios::binary);
  if (!binary) return std::string(std::istreambuf_iterator<char>(in), {});
  unsigned char header[20] = {};
  in.read(reinterpret_cast<char*>(header), sizeof header);
  if (in.gcount() != sizeof header) return {};
  const std::uint32_t length = std::uint32_t(header[12]) | std::uint32_t(header[13]) << 8 |
                               std::uint32_t(header[14]) << 16 | std::uint32_t(header[15]) << 24;
  std::string json(std::min<std::uint32_t>(length, 1u << 30), '\0');
  in.read(json.data(), static_cast<std::streamsize>(json.size()));
  json.resize(static_cast<std::size_t>(std::max<std::streamsize>(in.gcount(), 0)));
  return json;
}

// A file a relative glTF uri names (percent-decoded, as tinygltf opens it); empty for data: URIs.
std::string uri_file(const std::string& gltf, const std::string& uri) {
  if (uri.empty() || uri.rfind("data:", 0) == 0) return {};
  std::string decoded;
  for (std::size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] == '%' && i + 2 < uri.size() && std::isxdigit(static_cast<unsigned char>(uri[i + 1])) &&
        std::isxdigit(static_cast<unsigned char>(uri[i + 2]))) {
      decoded += static_cast<char>(std::stoi(uri.substr(i + 1, 2), nullptr, 16));
      i += 2;
    } else {
      decoded += uri[i];
    }
  }
  return (std::filesystem::path(gltf).parent_path() / decoded).string();
}

// A rotation quaternion must have a length to normalise: (0, 0, 0, 0) would silently become the identity
// (glm's normalize). Lengths of at least kMinRotationLength normalise exactly in float too.
bool usable_rotation(double x, double y, double z, double w) {
  const double len = std::sqrt(x * x + y * y + z * z + w * w);
  return std::isfinite(len) && len >= kMinRotationLength;
}


}  // namespace

Status Loader::load_node(std::size_t i) {
  const tinygltf::Node& src = model.nodes[i];
  Node& n = out.nodes[i];
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
  node_mesh[i] = src.mesh;
  n.skin = src.skin;
  node_camera[i] = src.camera;
  auto light = src.extensions.find("KHR_lights_punctual");
  if (light != src.extensions.end() && light->second.IsObject() && light->second.Has("light")) {
    node_light[i] = light->second.Get("light").GetNumberAsInt();
    if (Status s = check(node_light[i], model.lights.size(), "light"); !s) return s;
    if (node_light[i] < 0) return Error::input(file, "node " + quoted_or_index(src.name, i) + " names light -1");
  }
  // A transform that is not finite in float puts NaN into every matrix below it (docs/render-gbuffer.md: exit 2).
  auto finite = [](const std::vector<double>& v) {
    return std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(static_cast<float>(x)); });
  };
  if (!finite(src.matrix) || !finite(src.translation) || !finite(src.rotation) || !finite(src.scale)) {
    return Error::input(file, "node " + quoted_or_index(src.name, i) +
                                  " has a matrix, translation, rotation or scale that is not finite");
  }
  if (src.matrix.size() == 16) {
    n.matrix = glm::make_mat4(src.matrix.data());
    n.use_matrix = true;
  } else {
    if (src.translation.size() == 3) n.translation = glm::vec3(src.translation[0], src.translation[1], src.translation[2]);
    if (src.rotation.size() == 4) {
      const auto& q = src.rotation;
      if (!usable_rotation(q[0], q[1], q[2], q[3])) {
        return Error::input(file, "node " + quoted_or_index(src.name, i) +
                                      " has a rotation quaternion of length 0 (it must be a unit quaternion, x y z w)");
      }
      n.rotation = glm::normalize(glm::quat(static_cast<float>(q[3]), static_cast<float>(q[0]),
                                            static_cast<float>(q[1]), static_cast<float>(q[2])));
    }
    if (src.scale.size() == 3) n.scale = glm::vec3(src.scale[0], src.scale[1], src.scale[2]);
  }
  for (int c : src.children) {
    if (c < 0 || c >= static_cast<int>(model.nodes.size())) {
      return Error::input(file, "node " + quoted_or_index(src.name, i) + " has child " + std::to_string(c) +
                                    ", which does not exist");
    }
    Node& child = out.nodes[static_cast<std::size_t>(c)];
    if (child.parent >= 0 || static_cast<std::size_t>(c) == i) {
      return Error::input(file, "node " + std::to_string(c) + " has more than one parent (the node graph must be a forest)");
    }
    child.parent = static_cast<int>(i);
  }
  return Status::ok();
}

Status Loader::load_nodes_and_order() {
  const std::size_t count = model.nodes.size();
  out.nodes.resize(count);
  node_mesh.assign(count, -1);
  node_camera.assign(count, -1);
  node_light.assign(count, -1);
  for (std::size_t i = 0; i < count; ++i) {
    if (Status s = load_node(i); !s) return s;
  }
  // Parents-first order over every node (joints may sit outside the drawn scene), depth first from the roots.
  out.order.clear();
  for (std::size_t r = 0; r < count; ++r) {
    if (out.nodes[r].parent >= 0) continue;
    std::vector<int> stack{static_cast<int>(r)};
    while (!stack.empty()) {
      const int v = stack.back();
      stack.pop_back();
      out.order.push_back(v);
      const auto& ch = model.nodes[static_cast<std::size_t>(v)].children;
      for (auto it = ch.rbegin(); it != ch.rend(); ++it) stack.push_back(*it);
    }
  }
  if (out.order.size() != count) {
    return Error::input(file, "the node hierarchy has a cycle (a node is its own ancestor)");
  }
  // The drawn scene: `scene`, else scene 0, else every root.
  if (!model.scenes.empty()) {
    const int si = model.defaultScene >= 0 && model.defaultScene < static_cast<int>(model.scenes.size()) ? model.defaultScene : 0;
    for (int rnode : model.scenes[static_cast<std::size_t>(si)].nodes) {
      if (rnode < 0 || rnode >= static_cast<int>(count)) {
        return Error::input(file, "scene " + std::to_string(si) + " names node " + std::to_string(rnode) + ", which does not exist");
      }
    }
  }
  mark_drawn_scene();
  return Status::ok();
}

void Loader::mark_drawn_scene() {
  const std::size_t count = model.nodes.size();
  in_scene.assign(count, 0);
  std::vector<int> roots;
  if (!model.scenes.empty()) {
    const int si = model.defaultScene >= 0 && model.defaultScene < static_cast<int>(model.scenes.size()) ? model.defaultScene : 0;
    roots = model.scenes[static_cast<std::size_t>(si)].nodes;
  } else {
    for (std::size_t r = 0; r < count; ++r) {
      if (out.nodes[r].parent < 0) roots.push_back(static_cast<int>(r));
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
}

Status Loader::load_skins() {
  for (std::size_t i = 0; i < model.skins.size(); ++i) {
    const tinygltf::Skin& src = model.skins[i];
    Skin skin;
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
    out.skins.push_back(std::move(skin));
  }
  return Status::ok();
}

// Meshes drawn by the scene's nodes, each loaded once however many nodes draw it.
Status Loader::load_meshes() {
  mesh_primitives.assign(model.meshes.size(), {});
  mesh_targets.assign(model.meshes.size(), 0);
  std::vector<char> mesh_loaded(model.meshes.size(), 0), mesh_skinned(model.meshes.size(), 0);
  for (std::size_t v = 0; v < out.nodes.size(); ++v) {
    if (in_scene[v] && node_mesh[v] >= 0 && out.nodes[v].skin >= 0) mesh_skinned[static_cast<std::size_t>(node_mesh[v])] = 1;
  }
  for (int v : out.order) {
    const int mesh = node_mesh[static_cast<std::size_t>(v)];
    if (!in_scene[static_cast<std::size_t>(v)] || mesh < 0 || mesh_loaded[static_cast<std::size_t>(mesh)]) continue;
    mesh_loaded[static_cast<std::size_t>(mesh)] = 1;
    if (Status s = load_mesh(mesh, mesh_skinned[static_cast<std::size_t>(mesh)] != 0); !s) return s;
  }
  return Status::ok();
}

// Draw list and morph weight slots, in node order (stable, so evaluations pair index by index).
Status Loader::build_draws() {
  for (int v : out.order) {
    Node& n = out.nodes[static_cast<std::size_t>(v)];
    const int mesh_index = node_mesh[static_cast<std::size_t>(v)];
    if (!in_scene[static_cast<std::size_t>(v)] || mesh_index < 0) continue;
    const tinygltf::Mesh& mesh = model.meshes[static_cast<std::size_t>(mesh_index)];
    const int targets = mesh_targets[static_cast<std::size_t>(mesh_index)];
    if (targets > 0) {
      n.weight_offset = out.weight_total;
      n.weight_count = targets;
      out.weight_total += targets;
      const auto& src = model.nodes[static_cast<std::size_t>(v)].weights.size() == static_cast<std::size_t>(targets)
                            ? model.nodes[static_cast<std::size_t>(v)].weights
                            : mesh.weights;
      n.rest_weights.assign(static_cast<std::size_t>(targets), 0.0f);
      if (src.size() == static_cast<std::size_t>(targets)) {
        for (int k = 0; k < targets; ++k) n.rest_weights[static_cast<std::size_t>(k)] = static_cast<float>(src[static_cast<std::size_t>(k)]);
      }
    }
    for (int p : mesh_primitives[static_cast<std::size_t>(mesh_index)]) {
      if (p < 0) continue;
      const auto ps = static_cast<std::size_t>(p);
      if (n.skin >= 0 && out.primitive_data[ps].influences > 0 &&
          max_joint[ps] > out.skins[static_cast<std::size_t>(n.skin)].joints.size()) {
        return Error::input(file, "mesh " + quoted_or_index(mesh.name, static_cast<std::size_t>(mesh_index)) +
                                      " uses joint " + std::to_string(max_joint[ps] - 1) + " but skin " +
                                      std::to_string(n.skin) + " has only " +
                                      std::to_string(out.skins[static_cast<std::size_t>(n.skin)].joints.size()) + " joints");
      }
      out.draws.push_back({v, p});
    }
  }
  if (out.draws.empty()) {
    return Error::input(file, "the scene has no triangles to draw (no mesh with a triangle primitive in its node tree)");
  }
  return Status::ok();
}

// The animations a --clip value selects (Usage error listing the clips when none matches).
Status Loader::select_clips(const std::string& clip, std::vector<std::size_t>& selected) {
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
      return Error{ErrorKind::Usage, file, "no animation clip '" + clip + "' (have: " + join_names(out.clip_names) +
                                               "; give a name, an index or 'all')"};
    }
  }
  return Status::ok();
}

Status Loader::load_channel(std::size_t ai, std::size_t ci, std::map<int, int>& sampler_map, std::vector<char>& animated) {
  const tinygltf::Animation& anim = model.animations[ai];
  const tinygltf::AnimationChannel& ch = anim.channels[ci];
  const std::string what = "channel " + std::to_string(ci) + " of animation " + quoted_or_index(anim.name, ai);
  if (ch.target_node < 0) return Status::ok();  // no target: ignored (section 3.11: e.g. extension targets)
  if (ch.target_node >= static_cast<int>(out.nodes.size())) {
    return Error::input(file, what + " targets node " + std::to_string(ch.target_node) + ", which does not exist");
  }
  if (ch.sampler < 0 || ch.sampler >= static_cast<int>(anim.samplers.size())) {
    return Error::input(file, what + " names sampler " + std::to_string(ch.sampler) + ", which does not exist");
  }
  Channel channel;
  channel.node = ch.target_node;
  const Node& node = out.nodes[static_cast<std::size_t>(channel.node)];
  int components = 0;
  if (ch.target_path == "translation") { channel.path = TargetPath::Translation; components = 3; }
  else if (ch.target_path == "rotation") { channel.path = TargetPath::Rotation; components = 4; }
  else if (ch.target_path == "scale") { channel.path = TargetPath::Scale; components = 3; }
  else if (ch.target_path == "weights") {
    channel.path = TargetPath::Weights;
    components = node.weight_count;
    if (components == 0) {
      out.warnings.push_back(what + " animates morph weights of a node without morph targets: ignored");
      return Status::ok();
    }
  } else {
    out.warnings.push_back(what + " animates '" + ch.target_path + "': ignored");
    return Status::ok();
  }
  animated[static_cast<std::size_t>(channel.node)] = 1;
  auto known = sampler_map.find(ch.sampler);
  if (known != sampler_map.end() && out.samplers[static_cast<std::size_t>(known->second)].components == components) {
    channel.sampler = known->second;
    out.channels.push_back(channel);
    return Status::ok();
  }
  const tinygltf::AnimationSampler& src = anim.samplers[static_cast<std::size_t>(ch.sampler)];
  Sampler s;
  s.components = components;
  if (src.interpolation == "STEP") s.interpolation = Interpolation::Step;
  else if (src.interpolation == "CUBICSPLINE") s.interpolation = Interpolation::CubicSpline;
  else if (src.interpolation == "LINEAR" || src.interpolation.empty()) s.interpolation = Interpolation::Linear;
  else return Error::input(file, what + ": unknown interpolation '" + src.interpolation + "'");
  if (Status st = read_floats(model, src.input, 1, file, "input of " + what, s.times); !st) return st;
  if (s.times.empty()) {
    out.warnings.push_back(what + ": its sampler has no keyframes: ignored");
    return Status::ok();
  }
  if (Status st = read_floats(model, src.output, 0, file, "output of " + what, s.values); !st) return st;
  for (std::size_t k = 0; k < s.times.size(); ++k) {
    if (!std::isfinite(s.times[k]) || (k > 0 && s.times[k] < s.times[k - 1])) {
      return Error::input(file, "input of " + what + ": key times must be finite and increasing");
    }
  }
  const std::size_t expect = s.times.size() * static_cast<std::size_t>(components) *
                             (s.interpolation == Interpolation::CubicSpline ? 3u : 1u);
  if (s.values.size() != expect) {
    return Error::input(file, "output of " + what + " holds " + std::to_string(s.values.size()) + " values, expected " +
                                  std::to_string(expect) + " (" + std::to_string(s.times.size()) + " keys of " +
                                  std::to_string(components) + " for " + src.interpolation + ")");
  }
  if (!std::all_of(s.values.begin(), s.values.end(), [](float x) { return std::isfinite(x); })) {
    return Error::input(file, "output of " + what + " holds NaN or infinite values");
  }
  if (channel.path == TargetPath::Rotation) {
    // Keyframe values (for CUBICSPLINE the middle of each in-tangent, value, out-tangent triple; tangents may be 0).
    const std::size_t stride = s.interpolation == Interpolation::CubicSpline ? 12 : 4;
    const std::size_t first = s.interpolation == Interpolation::CubicSpline ? 4 : 0;
    for (std::size_t k = first; k + 4 <= s.values.size(); k += stride) {
      if (!usable_rotation(s.values[k], s.values[k + 1], s.values[k + 2], s.values[k + 3])) {
        return Error::input(file, "output of " + what + " (accessor " + std::to_string(src.output) +
                                      ") holds a rotation quaternion of length 0 at key " + std::to_string(k / stride));
      }
    }
  }
  out.clip_duration = std::max(out.clip_duration, static_cast<double>(s.times.back()));
  channel.sampler = static_cast<int>(out.samplers.size());
  sampler_map[ch.sampler] = channel.sampler;
  out.samplers.push_back(std::move(s));
  out.channels.push_back(channel);
  return Status::ok();
}

Status Loader::load_animations(const std::string& clip) {
  for (std::size_t i = 0; i < model.animations.size(); ++i) {
    out.clip_names.push_back(model.animations[i].name.empty() ? std::to_string(i) : model.animations[i].name);
  }
  out.clip_duration = 0.0;
  if (model.animations.empty()) {
    if (!clip.empty() && clip != "all") {
      return Error{ErrorKind::Usage, file, "clip '" + clip + "' asked for, but the scene has no animation"};
    }
    return Status::ok();
  }
  std::vector<std::size_t> selected;
  if (Status s = select_clips(clip, selected); !s) return s;
  std::vector<char> animated(out.nodes.size(), 0);
  for (std::size_t ai : selected) {
    std::map<int, int> sampler_map;  // this animation's sampler -> out.samplers
    for (std::size_t ci = 0; ci < model.animations[ai].channels.size(); ++ci) {
      if (Status s = load_channel(ai, ci, sampler_map, animated); !s) return s;
    }
  }
  // An animated node that gave `matrix` (the spec forbids it): decomposed into T, R, S so the channels apply.
  for (std::size_t i = 0; i < out.nodes.size(); ++i) {
    Node& n = out.nodes[i];
    if (!animated[i] || !n.use_matrix) continue;
    glm::vec3 skew;
    glm::vec4 persp;
    glm::decompose(n.matrix, n.scale, n.rotation, n.translation, skew, persp);
    n.use_matrix = false;
    out.warnings.push_back("node " + quoted_or_index(n.name, i) + " is animated but has a matrix: decomposed into TRS");
  }
  return Status::ok();
}

Status Loader::load_cameras_and_lights() {
  for (std::size_t i = 0; i < model.cameras.size(); ++i) {
    const tinygltf::Camera& c = model.cameras[i];
    CameraDef def;
    def.name = c.name.empty() ? std::to_string(i) : c.name;
    if (c.type == "orthographic") {
      def.orthographic = true;
    } else {
      def.yfov = static_cast<float>(c.perspective.yfov);
      def.aspect = static_cast<float>(c.perspective.aspectRatio);
      def.znear = static_cast<float>(c.perspective.znear);
      def.zfar = static_cast<float>(c.perspective.zfar);
      // yfov below kMinCameraYfov makes 1 / tan(yfov / 2) overflow float: a worldToNDC of NaN, blank frames.
      if (!(def.yfov >= kMinCameraYfov && def.yfov < 3.14f) || !(def.znear > 0.0f) || !std::isfinite(def.zfar) ||
          (def.zfar != 0.0f && !(def.zfar > def.znear))) {
        char yfov[32];
        std::snprintf(yfov, sizeof yfov, "%g", c.perspective.yfov);
        return Error::input(file, "camera " + quoted_or_index(c.name, i) + " has an invalid yfov (" + yfov +
                                      "; it must lie in [1e-4, 3.14) radians), znear or zfar");
      }
      if (def.aspect != 0.0f && !(def.aspect >= 1e-4f && def.aspect <= 1e4f)) {
        return Error::input(file, "camera " + quoted_or_index(c.name, i) + " has an aspectRatio outside [1e-4, 1e4]");
      }
    }
    out.cameras.push_back(def);
  }
  for (int v : out.order) {
    const auto vi = static_cast<std::size_t>(v);
    if (!in_scene[vi]) continue;
    if (node_camera[vi] >= 0) out.camera_instances.push_back({node_camera[vi], v});
    if (node_light[vi] < 0) continue;
    const tinygltf::Light& src = model.lights[static_cast<std::size_t>(node_light[vi])];
    LightDef def;
    def.node = v;
    if (src.type == "directional") def.light.type = LightState::Type::Directional;
    else if (src.type == "point") def.light.type = LightState::Type::Point;
    else if (src.type == "spot") def.light.type = LightState::Type::Spot;
    else {
      out.warnings.push_back("light " + std::to_string(node_light[vi]) + " has unknown type '" + src.type + "': ignored");
      continue;
    }
    if (src.color.size() == 3) def.light.color = glm::vec3(src.color[0], src.color[1], src.color[2]);
    def.light.intensity = static_cast<float>(src.intensity);
    def.light.range = static_cast<float>(src.range);
    def.light.inner_cone = static_cast<float>(src.spot.innerConeAngle);
    def.light.outer_cone = static_cast<float>(src.spot.outerConeAngle);
    out.lights.push_back(def);
  }
  return Status::ok();
}

Status read_gltf(const std::string& path, const SceneLoadOptions& options, SceneDescription& out) {
  // .glb is recognised by its magic, whatever the extension says.
  bool binary = false;
  {
    std::ifstream in(path, std::ios::binary);
    char magic[4] = {};
    in.read(magic, 4);
    binary = in.gcount() == 4 && std::string(magic, 4) == "glTF";
  }
  {
    std::size_t where = 0;
    if (json_depth(json_text(path, binary), &where) > kMaxJsonDepth) {
      return Error::input(path, "its JSON nests arrays and objects more than " + std::to_string(kMaxJsonDepth) +
                                    " deep (at byte " + std::to_string(where) + "): refused before parsing");
    }
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
  out.file = path;
  out.format = "glTF 2.0";
  // Every file the load read (render-gbuffer protects them from its outputs): the scene, its buffers and images.
  out.inputs.push_back(path);
  for (const tinygltf::Buffer& b : model.buffers)
    if (std::string f = uri_file(path, b.uri); !f.empty()) out.inputs.push_back(f);
  for (const tinygltf::Image& im : model.images)
    if (std::string f = uri_file(path, im.uri); !f.empty()) out.inputs.push_back(f);
  if (!warn.empty()) out.warnings.push_back(one_line(warn));
  Loader ld{model, path, out, {}, {}, {}, {}, {}, {}, {}, {}, {}, -1};
  if (Status s = ld.load_nodes_and_order(); !s) return s;
  if (Status s = ld.load_materials(); !s) return s;
  if (Status s = ld.load_meshes(); !s) return s;
  if (Status s = ld.load_skins(); !s) return s;
  if (Status s = ld.build_draws(); !s) return s;
  if (Status s = ld.load_animations(options.clip); !s) return s;
  return ld.load_cameras_and_lights();
}

}  // namespace temporal::scene_detail
