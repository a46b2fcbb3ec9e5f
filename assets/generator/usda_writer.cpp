// UsdaWriter (usda_writer.h). Numbers are written so that they read back exactly: floats from accessors with
// 9 significant digits, doubles of the glTF JSON with 17, time codes (120 per second) with 17. The layer's
// prims follow the glTF node order depth first, so the USD reader draws primitives in the glTF reader's order.
#include "usda_writer.h"

#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <glm/mat4x4.hpp>
#include <stb/stb_image_write.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <set>
#include <sstream>

namespace scenegen {
namespace {

constexpr double kTimeCodes = 120.0;  // time codes per second (and frames per second) of the written layers

std::string f9(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.9g", v);
  return b;
}
std::string f17(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.17g", v);
  return b;
}

// Elements of an accessor as float (tightly packed or strided; float, u8, u16, u32 components).
std::vector<float> read_floats(const tinygltf::Model& m, int index) {
  const tinygltf::Accessor& a = m.accessors[std::size_t(index)];
  const tinygltf::BufferView& v = m.bufferViews[std::size_t(a.bufferView)];
  const int comps = tinygltf::GetNumComponentsInType(std::uint32_t(a.type));
  const int size = tinygltf::GetComponentSizeInBytes(std::uint32_t(a.componentType));
  const std::size_t stride = v.byteStride ? v.byteStride : std::size_t(comps * size);
  const unsigned char* base = m.buffers[std::size_t(v.buffer)].data.data() + v.byteOffset + a.byteOffset;
  std::vector<float> out;
  for (std::size_t i = 0; i < a.count; ++i)
    for (int c = 0; c < comps; ++c) {
      const unsigned char* p = base + i * stride + std::size_t(c * size);
      switch (a.componentType) {
        case TINYGLTF_COMPONENT_TYPE_FLOAT: { float f; std::memcpy(&f, p, 4); out.push_back(f); break; }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: out.push_back(float(*p)); break;
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: { std::uint16_t u; std::memcpy(&u, p, 2); out.push_back(float(u)); break; }
        default: { std::uint32_t u; std::memcpy(&u, p, 4); out.push_back(float(u)); break; }
      }
    }
  return out;
}

std::string sanitize(const std::string& name, const std::string& fallback) {
  std::string s = name.empty() ? fallback : name;
  for (char& c : s)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_') c = '_';
  if (std::isdigit(static_cast<unsigned char>(s[0]))) s = "_" + s;
  return s;
}

// A glTF animation channel, its keys read as floats.
struct Track {
  std::string path;  // translation, rotation, scale, weights
  std::string interpolation;
  std::vector<float> times, values;
  int components = 0;
};

// The value of a LINEAR or STEP track at t, as the glTF reader of libtemporal computes it (same float
// operations), and of a CUBICSPLINE track likewise: baked samples then equal the reader's values bit for bit.
std::vector<float> sample(const Track& tr, float t) {
  const int c = tr.components;
  const std::size_t n = tr.times.size();
  const bool cubic = tr.interpolation == "CUBICSPLINE";
  auto value = [&](std::size_t k) { return tr.values.data() + (cubic ? (3 * k + 1) * std::size_t(c) : k * std::size_t(c)); };
  std::vector<float> out(static_cast<std::size_t>(c), 0.0f);
  if (n == 1 || t <= tr.times.front()) {
    std::copy_n(value(0), c, out.begin());
  } else if (t >= tr.times.back()) {
    std::copy_n(value(n - 1), c, out.begin());
  } else {
    const std::size_t k1 = std::size_t(std::upper_bound(tr.times.begin(), tr.times.end(), t) - tr.times.begin());
    const std::size_t k = k1 - 1;
    const float td = tr.times[k1] - tr.times[k];
    const float s = (t - tr.times[k]) / td;
    if (tr.interpolation == "STEP") {
      std::copy_n(value(k), c, out.begin());
    } else if (cubic) {
      const float s2 = s * s, s3 = s2 * s;
      const float h00 = 2 * s3 - 3 * s2 + 1, h10 = s3 - 2 * s2 + s, h01 = -2 * s3 + 3 * s2, h11 = s3 - s2;
      const float* v0 = value(k);
      const float* b0 = v0 + c;
      const float* v1 = value(k1);
      const float* a1 = v1 - c;
      for (int i = 0; i < c; ++i) out[std::size_t(i)] = h00 * v0[i] + h10 * td * b0[i] + h01 * v1[i] + h11 * td * a1[i];
    } else if (tr.path == "rotation") {
      // Only sampled at key times by this writer (asserted by the caller), where s = 0.
      std::copy_n(value(k), c, out.begin());
    } else {
      const float* a = value(k);
      const float* b = value(k1);
      for (int i = 0; i < c; ++i) out[std::size_t(i)] = a[i] + s * (b[i] - a[i]);
    }
  }
  if (tr.path == "rotation" && cubic) {
    const float len = std::sqrt(out[0] * out[0] + out[1] * out[1] + out[2] * out[2] + out[3] * out[3]);
    for (float& x : out) x /= len;
  }
  return out;
}

class Writer {
 public:
  Writer(const tinygltf::Model& m, std::string scene, std::vector<TextureFile>& textures)
      : m_(m), scene_(std::move(scene)), textures_(textures) {}

  std::string run(std::string& error) {
    if (!prepare(error)) return {};
    header();
    o_ << "def Xform \"Scene\" (\n    kind = \"assembly\"\n)\n{\n";
    materials();
    std::set<std::string> used = {"Materials"};
    for (int n : m_.scenes[0].nodes)
      if (!node(n, "/Scene", 1, used, error)) return {};
    o_ << "}\n";
    return o_.str();
  }

 private:
  bool prepare(std::string& error) {
    joint_skin_.assign(m_.nodes.size(), -1);
    for (std::size_t s = 0; s < m_.skins.size(); ++s) {
      if (m_.skins[s].skeleton < 0) return fail(error, "skin " + std::to_string(s) + " has no skeleton root node");
      for (int j : m_.skins[s].joints) joint_skin_[std::size_t(j)] = int(s);
      skins_of_root_[m_.skins[s].skeleton].push_back(int(s));
    }
    for (const auto& anim : m_.animations)
      for (const auto& ch : anim.channels) {
        const auto& smp = anim.samplers[std::size_t(ch.sampler)];
        Track t;
        t.path = ch.target_path;
        t.interpolation = smp.interpolation.empty() ? "LINEAR" : smp.interpolation;
        t.times = read_floats(m_, smp.input);
        t.values = read_floats(m_, smp.output);
        t.components = int(t.values.size() / t.times.size() / (t.interpolation == "CUBICSPLINE" ? 3 : 1));
        if (t.path == "rotation" && t.interpolation != "LINEAR")
          return fail(error, "rotation channels must be LINEAR (the writer does not bake rotation splines)");
        clip_ = std::max(clip_, double(t.times.back()));
        tracks_[ch.target_node].push_back(std::move(t));
      }
    return true;
  }

  static bool fail(std::string& error, const std::string& what) {
    error = what;
    return false;
  }

  void header() {
    o_ << "#usda 1.0\n(\n    defaultPrim = \"Scene\"\n"
       << "    doc = \"" << scene_ << ": written by temporal's scene-generator (assets/generator) from the same model as "
       << scene_ << ".glb\"\n";
    if (clip_ > 0.0) o_ << "    endTimeCode = " << f17(clip_ * kTimeCodes - 1.0) << "\n";
    o_ << "    framesPerSecond = " << f17(kTimeCodes) << "\n    metersPerUnit = 1\n";
    if (clip_ > 0.0) o_ << "    startTimeCode = 0\n";
    o_ << "    timeCodesPerSecond = " << f17(kTimeCodes) << "\n    upAxis = \"Y\"\n)\n\n";
  }

  std::string pad(int d) const { return std::string(std::size_t(4 * d), ' '); }

  // ---- materials and textures ------------------------------------------------------------------------------

  std::string texture_file(int texture) {
    const int source = m_.textures[std::size_t(texture)].source;
    auto known = texture_paths_.find(source);
    if (known != texture_paths_.end()) return known->second;
    const tinygltf::Image& img = m_.images[std::size_t(source)];
    TextureFile file;
    file.path = "textures/" + scene_ + "." + sanitize(img.name, "image" + std::to_string(source)) + ".png";
    stbi_write_png_to_func(
        [](void* ctx, void* data, int size) {
          auto* out = static_cast<std::vector<unsigned char>*>(ctx);
          out->insert(out->end(), static_cast<unsigned char*>(data), static_cast<unsigned char*>(data) + size);
        },
        &file.png, img.width, img.height, img.component, img.image.data(), 0);
    texture_paths_[source] = file.path;
    textures_.push_back(std::move(file));
    return textures_.back().path;
  }

  void materials() {
    o_ << "    def Scope \"Materials\"\n    {\n";
    std::set<std::string> used;
    for (std::size_t i = 0; i < m_.materials.size(); ++i) {
      const tinygltf::Material& mat = m_.materials[i];
      std::string name = sanitize(mat.name, "material" + std::to_string(i));
      while (!used.insert(name).second) name += "_";
      const std::string path = "/Scene/Materials/" + name;
      material_paths_.push_back(path);
      const auto& pbr = mat.pbrMetallicRoughness;
      const int tex = pbr.baseColorTexture.index;
      const std::vector<double> f = pbr.baseColorFactor.size() == 4 ? pbr.baseColorFactor : std::vector<double>{1, 1, 1, 1};
      o_ << "        def Material \"" << name << "\"\n        {\n"
         << "            token outputs:surface.connect = <" << path << "/Surface.outputs:surface>\n\n"
         << "            def Shader \"Surface\"\n            {\n"
         << "                uniform token info:id = \"UsdPreviewSurface\"\n";
      if (tex >= 0) {
        o_ << "                color3f inputs:diffuseColor.connect = <" << path << "/Texture.outputs:rgb>\n";
        if (mat.alphaMode != "OPAQUE") o_ << "                float inputs:opacity.connect = <" << path << "/Texture.outputs:a>\n";
      } else {
        o_ << "                color3f inputs:diffuseColor = (" << f17(f[0]) << ", " << f17(f[1]) << ", " << f17(f[2]) << ")\n";
        if (f[3] != 1.0) o_ << "                float inputs:opacity = " << f17(f[3]) << "\n";
      }
      if (mat.alphaMode == "MASK") o_ << "                float inputs:opacityThreshold = " << f17(mat.alphaCutoff) << "\n";
      o_ << "                float inputs:metallic = " << f17(pbr.metallicFactor) << "\n"
         << "                float inputs:roughness = " << f17(pbr.roughnessFactor) << "\n";
      const auto& e = mat.emissiveFactor;
      if (e.size() == 3 && (e[0] != 0.0 || e[1] != 0.0 || e[2] != 0.0))
        o_ << "                color3f inputs:emissiveColor = (" << f17(e[0]) << ", " << f17(e[1]) << ", " << f17(e[2]) << ")\n";
      o_ << "                token outputs:surface\n            }\n";
      if (tex >= 0) {
        const tinygltf::Sampler& s = m_.samplers[std::size_t(m_.textures[std::size_t(tex)].sampler)];
        auto wrap = [](int w) { return w == TINYGLTF_TEXTURE_WRAP_REPEAT ? "repeat" : w == TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT ? "mirror" : "clamp"; };
        o_ << "\n            def Shader \"Texture\"\n            {\n"
           << "                uniform token info:id = \"UsdUVTexture\"\n"
           << "                asset inputs:file = @" << texture_file(tex) << "@\n"
           << "                float4 inputs:scale = (" << f17(f[0]) << ", " << f17(f[1]) << ", " << f17(f[2]) << ", " << f17(f[3]) << ")\n"
           << "                float2 inputs:st.connect = <" << path << "/Primvar.outputs:result>\n"
           << "                token inputs:wrapS = \"" << wrap(s.wrapS) << "\"\n"
           << "                token inputs:wrapT = \"" << wrap(s.wrapT) << "\"\n"
           << "                float outputs:a\n                float3 outputs:rgb\n            }\n\n"
           << "            def Shader \"Primvar\"\n            {\n"
           << "                uniform token info:id = \"UsdPrimvarReader_float2\"\n"
           << "                string inputs:varname = \"st\"\n                float2 outputs:result\n            }\n";
      }
      o_ << "        }\n";
    }
    o_ << "    }\n";
  }

  // ---- nodes -----------------------------------------------------------------------------------------------

  const Track* track(int node, const std::string& path) const {
    auto it = tracks_.find(node);
    if (it == tracks_.end()) return nullptr;
    for (const Track& t : it->second)
      if (t.path == path) return &t;
    return nullptr;
  }

  // Key times of a track in time codes: its own keys (LINEAR, STEP) or one every 1/120 s (CUBICSPLINE).
  std::vector<double> time_codes(const Track& t) const {
    std::vector<double> tc;
    if (t.interpolation != "CUBICSPLINE") {
      for (float x : t.times) tc.push_back(double(x) * kTimeCodes);
      return tc;
    }
    const long last = std::lround(double(t.times.back()) * kTimeCodes);
    for (long k = 0; k <= last; ++k) tc.push_back(double(k));
    return tc;
  }

  void samples(const Track& t, int d, const std::string& decl, bool quat) {
    o_ << pad(d) << decl << ".timeSamples = {\n";
    for (double tc : time_codes(t)) {
      const std::vector<float> v = sample(t, float(tc / kTimeCodes));
      o_ << pad(d + 1) << f17(tc) << ": (";
      if (quat) o_ << f9(v[3]) << ", " << f9(v[0]) << ", " << f9(v[1]) << ", " << f9(v[2]);
      else o_ << f9(v[0]) << ", " << f9(v[1]) << ", " << f9(v[2]);
      o_ << "),\n";
    }
    o_ << pad(d) << "}\n";
  }

  void transform_ops(int n, int d) {
    const tinygltf::Node& nd = m_.nodes[std::size_t(n)];
    std::vector<std::string> order;
    const Track* t = track(n, "translation");
    const Track* r = track(n, "rotation");
    const Track* s = track(n, "scale");
    if (t) samples(*t, d, "double3 xformOp:translate", false);
    else if (nd.translation.size() == 3)
      o_ << pad(d) << "double3 xformOp:translate = (" << f17(nd.translation[0]) << ", " << f17(nd.translation[1]) << ", " << f17(nd.translation[2]) << ")\n";
    if (t || nd.translation.size() == 3) order.push_back("\"xformOp:translate\"");
    if (r) samples(*r, d, "quatf xformOp:orient", true);
    else if (nd.rotation.size() == 4)
      o_ << pad(d) << "quatf xformOp:orient = (" << f17(nd.rotation[3]) << ", " << f17(nd.rotation[0]) << ", " << f17(nd.rotation[1]) << ", " << f17(nd.rotation[2]) << ")\n";
    if (r || nd.rotation.size() == 4) order.push_back("\"xformOp:orient\"");
    if (s) samples(*s, d, "float3 xformOp:scale", false);
    else if (nd.scale.size() == 3)
      o_ << pad(d) << "float3 xformOp:scale = (" << f17(nd.scale[0]) << ", " << f17(nd.scale[1]) << ", " << f17(nd.scale[2]) << ")\n";
    if (s || nd.scale.size() == 3) order.push_back("\"xformOp:scale\"");
    if (order.empty()) return;
    o_ << pad(d) << "uniform token[] xformOpOrder = [";
    for (std::size_t i = 0; i < order.size(); ++i) o_ << (i ? ", " : "") << order[i];
    o_ << "]\n";
  }

  static std::string unique(std::set<std::string>& used, std::string name) {
    while (!used.insert(name).second) name += "_";
    return name;
  }

  bool node(int n, const std::string& parent_path, int d, std::set<std::string>& siblings, std::string& error) {
    const tinygltf::Node& nd = m_.nodes[std::size_t(n)];
    if (joint_skin_[std::size_t(n)] >= 0) {
      for (int c : nd.children)
        if (joint_skin_[std::size_t(c)] < 0) return fail(error, "joint node '" + nd.name + "' has a child that is not a joint");
      if (nd.mesh >= 0 || nd.camera >= 0) return fail(error, "joint node '" + nd.name + "' draws something");
      return true;  // written as a joint of its skeleton
    }
    const bool morph = nd.mesh >= 0 && !m_.meshes[std::size_t(nd.mesh)].primitives[0].targets.empty();
    const bool skel_root = skins_of_root_.count(n) > 0 || morph;
    const std::string name = unique(siblings, sanitize(nd.name, "node" + std::to_string(n)));
    const std::string path = parent_path + "/" + name;
    node_paths_[n] = path;
    o_ << "\n" << pad(d) << "def " << (skel_root ? "SkelRoot" : "Xform") << " \"" << name << "\"\n" << pad(d) << "{\n";
    transform_ops(n, d + 1);
    std::set<std::string> used;
    if (skins_of_root_.count(n)) {
      for (int s : skins_of_root_[n])
        if (!skeleton(s, path, d + 1, used, error)) return false;
    }
    if (morph) blend_skeleton(n, path, d + 1, used);
    if (nd.mesh >= 0 && !mesh(n, path, d + 1, used, error)) return false;
    if (nd.camera >= 0) camera(nd.camera, d + 1, used);
    auto light = nd.extensions.find("KHR_lights_punctual");
    if (light != nd.extensions.end()) punctual(light->second.Get("light").GetNumberAsInt(), d + 1, used);
    for (int c : nd.children)
      if (!node(c, path, d + 1, used, error)) return false;
    o_ << pad(d) << "}\n";
    return true;
  }

  void matrix(const glm::dmat4& m) {
    o_ << "(";
    for (int r = 0; r < 4; ++r)
      o_ << (r ? ", " : "") << "(" << f17(m[r][0]) << ", " << f17(m[r][1]) << ", " << f17(m[r][2]) << ", " << f17(m[r][3]) << ")";
    o_ << ")";
  }

  glm::dmat4 local(int n) const {
    const tinygltf::Node& nd = m_.nodes[std::size_t(n)];
    glm::dmat4 m(1.0);
    if (nd.translation.size() == 3) m = glm::translate(m, glm::dvec3(nd.translation[0], nd.translation[1], nd.translation[2]));
    if (nd.rotation.size() == 4) m = m * glm::mat4_cast(glm::dquat(nd.rotation[3], nd.rotation[0], nd.rotation[1], nd.rotation[2]));
    if (nd.scale.size() == 3) m = glm::scale(m, glm::dvec3(nd.scale[0], nd.scale[1], nd.scale[2]));
    return m;
  }

  bool skeleton(int s, const std::string& root_path, int d, std::set<std::string>& used, std::string& error) {
    const tinygltf::Skin& skin = m_.skins[std::size_t(s)];
    const std::string name = unique(used, m_.skins.size() == 1 || skins_of_root_[skin.skeleton].size() == 1 ? "Skeleton" : "Skeleton" + std::to_string(s));
    const std::string path = root_path + "/" + name;
    skeleton_paths_[s] = path;
    std::vector<std::string> joints;
    for (int j : skin.joints) {
      std::string p = sanitize(m_.nodes[std::size_t(j)].name, "joint" + std::to_string(j));
      for (int q = parent_of(j); q >= 0 && q != skin.skeleton; q = parent_of(q)) {
        if (joint_skin_[std::size_t(q)] != s) return fail(error, "a joint of skin " + std::to_string(s) + " hangs below a node that is not a joint");
        p = sanitize(m_.nodes[std::size_t(q)].name, "joint" + std::to_string(q)) + "/" + p;
      }
      joints.push_back(p);
    }
    const std::vector<float> ibm = read_floats(m_, skin.inverseBindMatrices);
    o_ << "\n" << pad(d) << "def Skeleton \"" << name << "\" (\n" << pad(d + 1) << "prepend apiSchemas = [\"SkelBindingAPI\"]\n" << pad(d) << ")\n" << pad(d) << "{\n";
    o_ << pad(d + 1) << "uniform token[] joints = [";
    for (std::size_t i = 0; i < joints.size(); ++i) o_ << (i ? ", " : "") << "\"" << joints[i] << "\"";
    o_ << "]\n" << pad(d + 1) << "uniform matrix4d[] bindTransforms = [";
    for (std::size_t i = 0; i < joints.size(); ++i) {
      o_ << (i ? ", " : "");
      matrix(glm::inverse(glm::dmat4(glm::make_mat4(&ibm[16 * i]))));
    }
    o_ << "]\n" << pad(d + 1) << "uniform matrix4d[] restTransforms = [";
    for (std::size_t i = 0; i < joints.size(); ++i) {
      o_ << (i ? ", " : "");
      matrix(local(skin.joints[i]));
    }
    o_ << "]\n" << pad(d + 1) << "rel skel:animationSource = <" << path << "/Animation>\n\n";
    o_ << pad(d + 1) << "def SkelAnimation \"Animation\"\n" << pad(d + 1) << "{\n" << pad(d + 2) << "uniform token[] joints = [";
    for (std::size_t i = 0; i < joints.size(); ++i) o_ << (i ? ", " : "") << "\"" << joints[i] << "\"";
    o_ << "]\n";
    if (!joint_arrays(skin, d + 2, "translation", "float3[] translations", error) ||
        !joint_arrays(skin, d + 2, "rotation", "quatf[] rotations", error) ||
        !joint_arrays(skin, d + 2, "scale", "half3[] scales", error))
      return false;
    o_ << pad(d + 1) << "}\n" << pad(d) << "}\n";
    return true;
  }

  int parent_of(int n) const {
    for (std::size_t p = 0; p < m_.nodes.size(); ++p)
      for (int c : m_.nodes[p].children)
        if (c == n) return int(p);
    return -1;
  }

  // One value per joint for `path` (the channel's value at tc, else the rest value), as text.
  std::string joint_values(const tinygltf::Skin& skin, const std::string& path, const double* tc) const {
    std::string s = "[";
    for (std::size_t i = 0; i < skin.joints.size(); ++i) {
      const int j = skin.joints[i];
      const tinygltf::Node& nd = m_.nodes[std::size_t(j)];
      const Track* t = tc ? track(j, path) : nullptr;
      s += i ? ", (" : "(";
      if (t) {
        const std::vector<float> v = sample(*t, float(*tc / kTimeCodes));
        s += path == "rotation" ? f9(v[3]) + ", " + f9(v[0]) + ", " + f9(v[1]) + ", " + f9(v[2])
                                : f9(v[0]) + ", " + f9(v[1]) + ", " + f9(v[2]);
      } else if (path == "translation") {
        const auto& v = nd.translation;
        s += v.size() == 3 ? f17(v[0]) + ", " + f17(v[1]) + ", " + f17(v[2]) : "0, 0, 0";
      } else if (path == "rotation") {
        const auto& v = nd.rotation;
        s += v.size() == 4 ? f17(v[3]) + ", " + f17(v[0]) + ", " + f17(v[1]) + ", " + f17(v[2]) : "1, 0, 0, 0";
      } else {
        const auto& v = nd.scale;
        s += v.size() == 3 ? f17(v[0]) + ", " + f17(v[1]) + ", " + f17(v[2]) : "1, 1, 1";
      }
      s += ")";
    }
    return s + "]";
  }

  bool joint_arrays(const tinygltf::Skin& skin, int d, const std::string& path, const std::string& decl, std::string& error) {
    std::set<double> times;
    for (int j : skin.joints)
      if (const Track* t = track(j, path))
        for (double tc : time_codes(*t)) times.insert(tc);
    // Rotations are only sampled at their own keys (sample() does not slerp): every joint's track must have
    // a key at every time of the union.
    for (int j : skin.joints)
      if (const Track* t = track(j, path); t && path == "rotation" && time_codes(*t).size() != times.size())
        return fail(error, "the rotation channels of skin joints have different key times");
    if (times.empty()) {
      o_ << pad(d) << decl << " = " << joint_values(skin, path, nullptr) << "\n";
      return true;
    }
    o_ << pad(d) << decl << ".timeSamples = {\n";
    for (double tc : times) o_ << pad(d + 1) << f17(tc) << ": " << joint_values(skin, path, &tc) << ",\n";
    o_ << pad(d) << "}\n";
    return true;
  }

  // A node whose mesh has morph targets: a joint-less Skeleton whose animation carries the weights.
  void blend_skeleton(int n, const std::string& root_path, int d, std::set<std::string>& used) {
    const tinygltf::Node& nd = m_.nodes[std::size_t(n)];
    const tinygltf::Mesh& mesh = m_.meshes[std::size_t(nd.mesh)];
    const std::size_t targets = mesh.primitives[0].targets.size();
    const std::string name = unique(used, "Skeleton");
    const std::string path = root_path + "/" + name;
    morph_skeleton_[n] = path;
    o_ << "\n" << pad(d) << "def Skeleton \"" << name << "\" (\n" << pad(d + 1) << "prepend apiSchemas = [\"SkelBindingAPI\"]\n"
       << pad(d) << ")\n" << pad(d) << "{\n" << pad(d + 1) << "uniform token[] joints = []\n"
       << pad(d + 1) << "rel skel:animationSource = <" << path << "/Animation>\n\n"
       << pad(d + 1) << "def SkelAnimation \"Animation\"\n" << pad(d + 1) << "{\n" << pad(d + 2) << "uniform token[] blendShapes = [";
    for (std::size_t k = 0; k < targets; ++k) o_ << (k ? ", " : "") << "\"target" << k << "\"";
    o_ << "]\n";
    const std::vector<double>& rest = nd.weights.size() == targets ? nd.weights : mesh.weights;
    auto list = [&](const float* v) {
      std::string s = "[";
      for (std::size_t k = 0; k < targets; ++k) s += (k ? ", " : "") + (v ? f9(v[k]) : f17(k < rest.size() ? rest[k] : 0.0));
      return s + "]";
    };
    if (const Track* t = track(n, "weights")) {
      o_ << pad(d + 2) << "float[] blendShapeWeights.timeSamples = {\n";
      for (double tc : time_codes(*t)) {
        const std::vector<float> v = sample(*t, float(tc / kTimeCodes));
        o_ << pad(d + 3) << f17(tc) << ": " << list(v.data()) << ",\n";
      }
      o_ << pad(d + 2) << "}\n";
    } else {
      o_ << pad(d + 2) << "float[] blendShapeWeights = " << list(nullptr) << "\n";
    }
    o_ << pad(d + 1) << "}\n" << pad(d) << "}\n";
  }

  void vec3s(const std::vector<float>& v, std::size_t first, std::size_t count) {
    o_ << "[";
    for (std::size_t i = first; i < first + count; ++i)
      o_ << (i > first ? ", " : "") << "(" << f9(v[3 * i]) << ", " << f9(v[3 * i + 1]) << ", " << f9(v[3 * i + 2]) << ")";
    o_ << "]";
  }

  bool mesh(int n, const std::string& node_path, int d, std::set<std::string>& used, std::string& error) {
    const tinygltf::Node& nd = m_.nodes[std::size_t(n)];
    const tinygltf::Mesh& mesh = m_.meshes[std::size_t(nd.mesh)];
    if (mesh.primitives.size() != 1) return fail(error, "mesh '" + mesh.name + "' has more than one primitive");
    const tinygltf::Primitive& prim = mesh.primitives[0];
    if (prim.mode != TINYGLTF_MODE_TRIANGLES && prim.mode != -1) return fail(error, "mesh '" + mesh.name + "' is not a triangle list");
    const std::vector<float> pos = read_floats(m_, prim.attributes.at("POSITION"));
    const std::vector<float> idx = read_floats(m_, prim.indices);
    const std::size_t nv = pos.size() / 3;
    const std::string name = unique(used, "mesh");
    const std::string path = node_path + "/" + name;
    const bool skinned = nd.skin >= 0;
    const bool morph = !prim.targets.empty();
    o_ << "\n" << pad(d) << "def Mesh \"" << name << "\"" << (skinned || morph ? " (\n" + pad(d + 1) + "prepend apiSchemas = [\"SkelBindingAPI\", \"MaterialBindingAPI\"]\n" + pad(d) + ")" : " (\n" + pad(d + 1) + "prepend apiSchemas = [\"MaterialBindingAPI\"]\n" + pad(d) + ")") << "\n" << pad(d) << "{\n";
    const int mat = prim.material;
    if (mat >= 0 && m_.materials[std::size_t(mat)].doubleSided) o_ << pad(d + 1) << "uniform bool doubleSided = 1\n";
    o_ << pad(d + 1) << "int[] faceVertexCounts = [";
    for (std::size_t t = 0; t < idx.size() / 3; ++t) o_ << (t ? ", 3" : "3");
    o_ << "]\n" << pad(d + 1) << "int[] faceVertexIndices = [";
    for (std::size_t i = 0; i < idx.size(); ++i) o_ << (i ? ", " : "") << std::uint32_t(idx[i]);
    o_ << "]\n";
    if (mat >= 0) o_ << pad(d + 1) << "rel material:binding = <" << material_paths_[std::size_t(mat)] << ">\n";
    if (prim.attributes.count("NORMAL")) {
      o_ << pad(d + 1) << "normal3f[] normals = ";
      vec3s(read_floats(m_, prim.attributes.at("NORMAL")), 0, nv);
      o_ << " (\n" << pad(d + 2) << "interpolation = \"vertex\"\n" << pad(d + 1) << ")\n";
    }
    o_ << pad(d + 1) << "point3f[] points = ";
    vec3s(pos, 0, nv);
    o_ << "\n";
    if (prim.attributes.count("TEXCOORD_0")) {
      const std::vector<float> uv = read_floats(m_, prim.attributes.at("TEXCOORD_0"));
      o_ << pad(d + 1) << "texCoord2f[] primvars:st = [";
      for (std::size_t i = 0; i < nv; ++i) o_ << (i ? ", " : "") << "(" << f9(uv[2 * i]) << ", " << f9(1.0 - double(uv[2 * i + 1])) << ")";
      o_ << "] (\n" << pad(d + 2) << "interpolation = \"vertex\"\n" << pad(d + 1) << ")\n";
    }
    if (skinned) {
      const std::vector<float> j = read_floats(m_, prim.attributes.at("JOINTS_0"));
      const std::vector<float> w = read_floats(m_, prim.attributes.at("WEIGHTS_0"));
      o_ << pad(d + 1) << "int[] primvars:skel:jointIndices = [";
      for (std::size_t i = 0; i < j.size(); ++i) o_ << (i ? ", " : "") << std::uint32_t(j[i]);
      o_ << "] (\n" << pad(d + 2) << "elementSize = 4\n" << pad(d + 2) << "interpolation = \"vertex\"\n" << pad(d + 1) << ")\n";
      o_ << pad(d + 1) << "float[] primvars:skel:jointWeights = [";
      for (std::size_t i = 0; i < w.size(); ++i) o_ << (i ? ", " : "") << f9(w[i]);
      o_ << "] (\n" << pad(d + 2) << "elementSize = 4\n" << pad(d + 2) << "interpolation = \"vertex\"\n" << pad(d + 1) << ")\n";
      o_ << pad(d + 1) << "rel skel:skeleton = <" << skeleton_paths_.at(nd.skin) << ">\n";
    }
    if (morph) {
      o_ << pad(d + 1) << "uniform token[] skel:blendShapes = [";
      for (std::size_t k = 0; k < prim.targets.size(); ++k) o_ << (k ? ", " : "") << "\"target" << k << "\"";
      o_ << "]\n" << pad(d + 1) << "rel skel:blendShapeTargets = [";
      for (std::size_t k = 0; k < prim.targets.size(); ++k) o_ << (k ? ", " : "") << "<" << path << "/target" << k << ">";
      o_ << "]\n" << pad(d + 1) << "rel skel:skeleton = <" << morph_skeleton_.at(n) << ">\n";
    }
    o_ << pad(d + 1) << "uniform token subdivisionScheme = \"none\"\n";
    for (std::size_t k = 0; k < prim.targets.size(); ++k) {
      o_ << "\n" << pad(d + 1) << "def BlendShape \"target" << k << "\"\n" << pad(d + 1) << "{\n" << pad(d + 2) << "uniform vector3f[] offsets = ";
      vec3s(read_floats(m_, prim.targets[k].at("POSITION")), 0, nv);
      o_ << "\n" << pad(d + 1) << "}\n";
    }
    o_ << pad(d) << "}\n";
    return true;
  }

  void camera(int c, int d, std::set<std::string>& used) {
    const tinygltf::Camera& cam = m_.cameras[std::size_t(c)];
    // focalLength 50 and verticalAperture 100 tan(yfov / 2): the reader's 2 atan(aperture / (2 focal)) gives yfov back.
    const double aperture = 100.0 * std::tan(0.5 * cam.perspective.yfov);
    o_ << "\n" << pad(d) << "def Camera \"" << unique(used, sanitize(cam.name, "camera")) << "\"\n" << pad(d) << "{\n"
       << pad(d + 1) << "float2 clippingRange = (" << f17(cam.perspective.znear) << ", " << f17(cam.perspective.zfar) << ")\n"
       << pad(d + 1) << "float focalLength = 50\n"
       << pad(d + 1) << "float horizontalAperture = " << f17(aperture * 1.25) << "\n"
       << pad(d + 1) << "token projection = \"perspective\"\n"
       << pad(d + 1) << "float verticalAperture = " << f17(aperture) << "\n" << pad(d) << "}\n";
  }

  void punctual(int l, int d, std::set<std::string>& used) {
    const tinygltf::Light& light = m_.lights[std::size_t(l)];
    const std::vector<double> c = light.color.size() == 3 ? light.color : std::vector<double>{1, 1, 1};
    const bool distant = light.type == "directional";
    o_ << "\n" << pad(d) << "def " << (distant ? "DistantLight" : "SphereLight") << " \"" << unique(used, sanitize(light.name, "light")) << "\"";
    if (light.type == "spot") o_ << " (\n" << pad(d + 1) << "prepend apiSchemas = [\"ShapingAPI\"]\n" << pad(d) << ")";
    o_ << "\n" << pad(d) << "{\n" << pad(d + 1) << "color3f inputs:color = (" << f17(c[0]) << ", " << f17(c[1]) << ", " << f17(c[2]) << ")\n"
       << pad(d + 1) << "float inputs:intensity = " << f17(light.intensity) << "\n";
    if (!distant) {
      // Candela: a normalized point-like sphere light (docs/usd.md, UsdLux conversion).
      o_ << pad(d + 1) << "bool inputs:normalize = 1\n" << pad(d + 1) << "float inputs:radius = 0\n"
         << pad(d + 1) << "bool treatAsPoint = 1\n";
    }
    if (light.type == "spot") {
      const double outer = light.spot.outerConeAngle, inner = light.spot.innerConeAngle;
      o_ << pad(d + 1) << "float inputs:shaping:cone:angle = " << f17(outer * 180.0 / 3.14159265358979323846) << "\n"
         << pad(d + 1) << "float inputs:shaping:cone:softness = " << f17(outer > 0.0 ? 1.0 - inner / outer : 0.0) << "\n";
    }
    o_ << pad(d) << "}\n";
  }

  const tinygltf::Model& m_;
  std::string scene_;
  std::vector<TextureFile>& textures_;
  std::ostringstream o_;
  double clip_ = 0.0;
  std::vector<int> joint_skin_;
  std::map<int, std::vector<int>> skins_of_root_;
  std::map<int, std::vector<Track>> tracks_;
  std::map<int, std::string> node_paths_, skeleton_paths_, morph_skeleton_;
  std::map<int, std::string> texture_paths_;
  std::vector<std::string> material_paths_;
};

}  // namespace

std::string write_usda(const tinygltf::Model& model, const std::string& scene_name, std::vector<TextureFile>& textures,
                       std::string& error) {
  return Writer(model, scene_name, textures).run(error);
}

}  // namespace scenegen
