// GltfBuilder implementation: one binary buffer, one bufferView per accessor, 4-byte aligned.
#include "gltf_builder.h"

#include <glm/gtc/type_ptr.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>

namespace scenegen {

double quantize(double v) { return std::round(v * 65536.0) / 65536.0; }

void MeshData::append(const MeshData& other, const glm::mat4& xf) {
  const auto base = static_cast<std::uint32_t>(positions.size());
  const glm::mat3 nm = glm::transpose(glm::inverse(glm::mat3(xf)));
  for (const auto& p : other.positions) positions.push_back(glm::vec3(xf * glm::vec4(p, 1.0f)));
  for (const auto& n : other.normals) normals.push_back(glm::normalize(nm * n));
  texcoords.insert(texcoords.end(), other.texcoords.begin(), other.texcoords.end());
  for (auto i : other.indices) indices.push_back(base + i);
  joints.insert(joints.end(), other.joints.begin(), other.joints.end());
  weights.insert(weights.end(), other.weights.begin(), other.weights.end());
}

void MeshData::bind_all(int joint) {
  joints.assign(positions.size(), glm::u16vec4(static_cast<std::uint16_t>(joint), 0, 0, 0));
  weights.assign(positions.size(), glm::vec4(1.0f, 0.0f, 0.0f, 0.0f));
}

GltfBuilder::GltfBuilder() {
  model_.asset.version = "2.0";
  model_.asset.generator = "temporal scene-generator (assets/generator)";
  model_.scenes.resize(1);
  model_.defaultScene = 0;
  model_.buffers.resize(1);
}

int GltfBuilder::add_accessor(const void* data, std::size_t bytes, int component_type, std::size_t count, int type,
                              int target, const std::vector<double>& min, const std::vector<double>& max) {
  while (buffer_.size() % 4) buffer_.push_back(0);
  tinygltf::BufferView view;
  view.buffer = 0;
  view.byteOffset = buffer_.size();
  view.byteLength = bytes;
  view.target = target;
  buffer_.resize(buffer_.size() + bytes);
  std::memcpy(buffer_.data() + view.byteOffset, data, bytes);
  model_.bufferViews.push_back(view);
  tinygltf::Accessor acc;
  acc.bufferView = static_cast<int>(model_.bufferViews.size()) - 1;
  acc.componentType = component_type;
  acc.count = count;
  acc.type = type;
  acc.minValues = min;
  acc.maxValues = max;
  model_.accessors.push_back(acc);
  return static_cast<int>(model_.accessors.size()) - 1;
}

int GltfBuilder::add_floats(std::vector<float> values, int type, int target, bool minmax) {
  const int comps = tinygltf::GetNumComponentsInType(static_cast<std::uint32_t>(type));
  for (float& v : values) v = static_cast<float>(quantize(v));
  std::vector<double> lo, hi;
  if (minmax && !values.empty()) {
    lo.assign(static_cast<std::size_t>(comps), 1e300);
    hi.assign(static_cast<std::size_t>(comps), -1e300);
    for (std::size_t i = 0; i < values.size(); ++i) {
      const std::size_t c = i % static_cast<std::size_t>(comps);
      lo[c] = std::min(lo[c], static_cast<double>(values[i]));
      hi[c] = std::max(hi[c], static_cast<double>(values[i]));
    }
  }
  return add_accessor(values.data(), values.size() * sizeof(float), TINYGLTF_COMPONENT_TYPE_FLOAT,
                      values.size() / static_cast<std::size_t>(comps), type, target, lo, hi);
}

int GltfBuilder::add_texture(const TextureDesc& t) {
  tinygltf::Image img;
  img.name = t.name;
  img.width = t.width;
  img.height = t.height;
  img.component = 4;
  img.bits = 8;
  img.pixel_type = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
  img.mimeType = "image/png";
  img.image = t.rgba;  // encoded to PNG (stb) and embedded as a data URI when written
  model_.images.push_back(img);
  tinygltf::Sampler s;
  s.wrapS = s.wrapT = t.repeat ? TINYGLTF_TEXTURE_WRAP_REPEAT : TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE;
  s.magFilter = t.nearest_mag ? TINYGLTF_TEXTURE_FILTER_NEAREST : TINYGLTF_TEXTURE_FILTER_LINEAR;
  s.minFilter = TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_LINEAR;
  model_.samplers.push_back(s);
  tinygltf::Texture tex;
  tex.name = t.name;
  tex.source = static_cast<int>(model_.images.size()) - 1;
  tex.sampler = static_cast<int>(model_.samplers.size()) - 1;
  model_.textures.push_back(tex);
  return static_cast<int>(model_.textures.size()) - 1;
}

int GltfBuilder::add_material(const MaterialDesc& m) {
  tinygltf::Material mat;
  mat.name = m.name;
  mat.pbrMetallicRoughness.baseColorFactor = {quantize(m.base_color.r), quantize(m.base_color.g),
                                              quantize(m.base_color.b), quantize(m.base_color.a)};
  mat.pbrMetallicRoughness.baseColorTexture.index = m.texture;
  mat.pbrMetallicRoughness.metallicFactor = quantize(m.metallic);
  mat.pbrMetallicRoughness.roughnessFactor = quantize(m.roughness);
  mat.emissiveFactor = {quantize(m.emissive.r), quantize(m.emissive.g), quantize(m.emissive.b)};
  mat.alphaMode = m.alpha_mode;
  mat.alphaCutoff = quantize(m.alpha_cutoff);
  mat.doubleSided = m.double_sided;
  model_.materials.push_back(mat);
  return static_cast<int>(model_.materials.size()) - 1;
}

int GltfBuilder::add_mesh(const std::string& name, const MeshData& d, int material,
                          const std::vector<float>& default_weights) {
  tinygltf::Primitive prim;
  prim.mode = TINYGLTF_MODE_TRIANGLES;
  prim.material = material;
  std::vector<float> f;
  auto flat3 = [](const std::vector<glm::vec3>& v) {
    std::vector<float> out;
    for (const auto& x : v) out.insert(out.end(), {x.x, x.y, x.z});
    return out;
  };
  prim.attributes["POSITION"] = add_floats(flat3(d.positions), TINYGLTF_TYPE_VEC3, TINYGLTF_TARGET_ARRAY_BUFFER, true);
  if (!d.normals.empty()) prim.attributes["NORMAL"] = add_floats(flat3(d.normals), TINYGLTF_TYPE_VEC3, TINYGLTF_TARGET_ARRAY_BUFFER);
  if (!d.texcoords.empty()) {
    for (const auto& t : d.texcoords) f.insert(f.end(), {t.x, t.y});
    prim.attributes["TEXCOORD_0"] = add_floats(f, TINYGLTF_TYPE_VEC2, TINYGLTF_TARGET_ARRAY_BUFFER);
  }
  if (!d.joints.empty()) {
    std::vector<std::uint16_t> j;
    for (const auto& x : d.joints) j.insert(j.end(), {x.x, x.y, x.z, x.w});
    prim.attributes["JOINTS_0"] = add_accessor(j.data(), j.size() * 2, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT,
                                               d.joints.size(), TINYGLTF_TYPE_VEC4, TINYGLTF_TARGET_ARRAY_BUFFER);
    f.clear();
    for (const auto& w : d.weights) f.insert(f.end(), {w.x, w.y, w.z, w.w});
    prim.attributes["WEIGHTS_0"] = add_floats(f, TINYGLTF_TYPE_VEC4, TINYGLTF_TARGET_ARRAY_BUFFER);
  }
  for (const auto& target : d.morph_positions) {
    prim.targets.push_back({{"POSITION", add_floats(flat3(target), TINYGLTF_TYPE_VEC3, TINYGLTF_TARGET_ARRAY_BUFFER, true)}});
  }
  const bool small = d.positions.size() < 65536;
  if (small) {
    std::vector<std::uint16_t> idx(d.indices.begin(), d.indices.end());
    prim.indices = add_accessor(idx.data(), idx.size() * 2, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, idx.size(),
                                TINYGLTF_TYPE_SCALAR, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
  } else {
    prim.indices = add_accessor(d.indices.data(), d.indices.size() * 4, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT,
                                d.indices.size(), TINYGLTF_TYPE_SCALAR, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
  }
  tinygltf::Mesh mesh;
  mesh.name = name;
  mesh.primitives.push_back(prim);
  for (float w : default_weights) mesh.weights.push_back(quantize(w));
  model_.meshes.push_back(mesh);
  triangles_ += d.triangles();
  return static_cast<int>(model_.meshes.size()) - 1;
}

int GltfBuilder::add_node(const std::string& name, int parent, const glm::vec3& t, const glm::quat& r, const glm::vec3& s) {
  tinygltf::Node node;
  node.name = name;
  if (t != glm::vec3(0.0f)) node.translation = {quantize(t.x), quantize(t.y), quantize(t.z)};
  if (r != glm::quat(1.0f, 0.0f, 0.0f, 0.0f)) {
    const glm::quat q = glm::normalize(r);
    node.rotation = {quantize(q.x), quantize(q.y), quantize(q.z), quantize(q.w)};
  }
  if (s != glm::vec3(1.0f)) node.scale = {quantize(s.x), quantize(s.y), quantize(s.z)};
  model_.nodes.push_back(node);
  const int index = static_cast<int>(model_.nodes.size()) - 1;
  if (parent >= 0) {
    model_.nodes[static_cast<std::size_t>(parent)].children.push_back(index);
  } else {
    model_.scenes[0].nodes.push_back(index);
  }
  return index;
}

void GltfBuilder::set_mesh(int node, int mesh) { model_.nodes[static_cast<std::size_t>(node)].mesh = mesh; }

void GltfBuilder::set_skin(int node, const std::vector<int>& joints, const std::vector<glm::mat4>& inverse_bind, int skeleton) {
  std::vector<float> f;
  for (const auto& m : inverse_bind) f.insert(f.end(), glm::value_ptr(m), glm::value_ptr(m) + 16);
  tinygltf::Skin skin;
  skin.joints = joints;
  skin.skeleton = skeleton;
  skin.inverseBindMatrices = add_floats(f, TINYGLTF_TYPE_MAT4);
  model_.skins.push_back(skin);
  model_.nodes[static_cast<std::size_t>(node)].skin = static_cast<int>(model_.skins.size()) - 1;
}

void GltfBuilder::set_camera(int node, const std::string& name, float yfov, float znear, float zfar) {
  tinygltf::Camera cam;
  cam.name = name;
  cam.type = "perspective";
  cam.perspective.yfov = quantize(yfov);
  cam.perspective.znear = quantize(znear);
  cam.perspective.zfar = quantize(zfar);
  model_.cameras.push_back(cam);
  model_.nodes[static_cast<std::size_t>(node)].camera = static_cast<int>(model_.cameras.size()) - 1;
}

void GltfBuilder::set_light(int node, const LightDesc& l) {
  tinygltf::Light light;
  light.name = l.name;
  light.type = l.type;
  light.color = {quantize(l.color.r), quantize(l.color.g), quantize(l.color.b)};
  light.intensity = quantize(l.intensity);
  light.range = quantize(l.range);
  if (l.type == "spot") {
    light.spot.innerConeAngle = quantize(l.inner_cone);
    light.spot.outerConeAngle = quantize(l.outer_cone);
  }
  model_.lights.push_back(light);
  tinygltf::Value::Object ext;
  ext["light"] = tinygltf::Value(static_cast<int>(model_.lights.size()) - 1);
  model_.nodes[static_cast<std::size_t>(node)].extensions["KHR_lights_punctual"] = tinygltf::Value(ext);
}

void GltfBuilder::animate(int node, const std::string& path, const std::vector<float>& times,
                          const std::vector<float>& values, const std::string& interpolation) {
  tinygltf::AnimationSampler s;
  s.input = add_floats(times, TINYGLTF_TYPE_SCALAR, 0, true);
  const int type = path == "rotation" ? TINYGLTF_TYPE_VEC4 : path == "weights" ? TINYGLTF_TYPE_SCALAR : TINYGLTF_TYPE_VEC3;
  s.output = add_floats(values, type);
  s.interpolation = interpolation;
  animation_.samplers.push_back(s);
  tinygltf::AnimationChannel ch;
  ch.sampler = static_cast<int>(animation_.samplers.size()) - 1;
  ch.target_node = node;
  ch.target_path = path;
  animation_.channels.push_back(ch);
}

tinygltf::Model GltfBuilder::model() const {
  tinygltf::Model model = model_;
  if (!animation_.channels.empty()) {
    tinygltf::Animation a = animation_;
    a.name = clip_name_;
    model.animations.push_back(a);
  }
  model.buffers[0].data = buffer_;
  return model;
}

std::vector<unsigned char> GltfBuilder::glb() {
  tinygltf::Model model = this->model();
  std::ostringstream out;
  tinygltf::TinyGLTF writer;
  writer.WriteGltfSceneToStream(&model, out, false, true);
  const std::string s = out.str();
  return std::vector<unsigned char>(s.begin(), s.end());
}

}  // namespace scenegen
