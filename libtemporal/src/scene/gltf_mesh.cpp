// glTF textures, materials and meshes: images to RGBA8, KHR_texture_transform baked into the texture
// coordinates, primitives to triangle lists with skin influences and morph displacements.
#include "gltf_reader.h"
#include "scene_mesh.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace temporal::scene_detail {
namespace {

// Reads attribute `name` of primitive `prim` when present; checks its element count.
Status read_attribute(const tinygltf::Model& model, const std::map<std::string, int>& attrs, const std::string& name,
                      int components, std::size_t count, const std::string& file, const std::string& what,
                      std::vector<float>& out, bool* present) {
  auto it = attrs.find(name);
  *present = it != attrs.end();
  if (!*present) return Status::ok();
  if (Status s = read_floats(model, it->second, components, file, name + " of " + what, out); !s) return s;
  if (out.size() != count * static_cast<std::size_t>(components)) {
    return Error::input(file, name + " of " + what + " has " + std::to_string(out.size() / components) +
                                  " elements, POSITION has " + std::to_string(count));
  }
  return Status::ok();
}

std::vector<glm::vec3> to_vec3(const std::vector<float>& f) {
  std::vector<glm::vec3> v(f.size() / 3);
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = glm::vec3(f[3 * i], f[3 * i + 1], f[3 * i + 2]);
  return v;
}

}  // namespace

Status Loader::load_texture(int gltf_texture, int* out_index) {
  auto found = texture_map.find(gltf_texture);
  if (found != texture_map.end()) {
    *out_index = found->second;
    return Status::ok();
  }
  if (gltf_texture < 0 || gltf_texture >= static_cast<int>(model.textures.size())) {
    return Error::input(file, "texture " + std::to_string(gltf_texture) + " does not exist (the file has " +
                                  std::to_string(model.textures.size()) + ")");
  }
  const tinygltf::Texture& tex = model.textures[static_cast<std::size_t>(gltf_texture)];
  if (tex.source < 0) {
    // A texture whose image is given only by an extension (KHR_texture_basisu, EXT_texture_webp, ...).
    out.warnings.push_back("texture " + std::to_string(gltf_texture) +
                            " has no PNG/JPEG source (only an extension image): drawn without it");
    *out_index = -1;
    texture_map[gltf_texture] = -1;
    return Status::ok();
  }
  if (tex.source >= static_cast<int>(model.images.size())) {
    return Error::input(file, "texture " + std::to_string(gltf_texture) + " names image " +
                                  std::to_string(tex.source) + ", which does not exist");
  }
  const tinygltf::Image& img = model.images[static_cast<std::size_t>(tex.source)];
  if (img.image.empty() || img.width <= 0 || img.height <= 0) {
    return Error::input(file, "image " + std::to_string(tex.source) +
                                  (img.uri.empty() ? std::string() : " ('" + img.uri + "')") +
                                  " could not be loaded or decoded: the file is missing or not a PNG/JPEG; "
                                  "place it beside the .gltf or fix its uri");
  }
  if ((img.bits != 8 && img.bits != 16) || img.component < 1 || img.component > 4) {
    return Error::input(file, "image " + std::to_string(tex.source) + " has an unsupported format (" +
                                  std::to_string(img.component) + " channels of " + std::to_string(img.bits) +
                                  " bits)");
  }
  const std::size_t pixels = static_cast<std::size_t>(img.width) * static_cast<std::size_t>(img.height);
  const std::size_t bytes_per = static_cast<std::size_t>(img.bits / 8);
  const std::size_t comp = static_cast<std::size_t>(img.component);
  if (img.image.size() < pixels * comp * bytes_per) {
    return Error::input(file, "image " + std::to_string(tex.source) + " holds fewer bytes than its size says");
  }
  SceneTexture tex_out;
  tex_out.width = img.width;
  tex_out.height = img.height;
  tex_out.rgba8.resize(pixels * 4);
  for (std::size_t i = 0; i < pixels; ++i) {
    std::uint8_t c[4] = {0, 0, 0, 255};
    for (std::size_t k = 0; k < comp; ++k) {
      // 16-bit images keep their high byte (little-endian storage from stb).
      c[k] = img.image[(i * comp + k) * bytes_per + (bytes_per - 1)];
    }
    if (comp == 1) c[1] = c[2] = c[0];
    if (comp == 2) { c[3] = c[1]; c[1] = c[2] = c[0]; }
    std::copy_n(c, 4, &tex_out.rgba8[i * 4]);
  }
  if (tex.sampler >= 0) {
    if (tex.sampler >= static_cast<int>(model.samplers.size())) {
      return Error::input(file, "texture " + std::to_string(gltf_texture) + " names sampler " +
                                    std::to_string(tex.sampler) + ", which does not exist");
    }
    const tinygltf::Sampler& s = model.samplers[static_cast<std::size_t>(tex.sampler)];
    tex_out.repeat_s = s.wrapS == TINYGLTF_TEXTURE_WRAP_REPEAT;
    tex_out.mirror_s = s.wrapS == TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT;
    tex_out.repeat_t = s.wrapT == TINYGLTF_TEXTURE_WRAP_REPEAT;
    tex_out.mirror_t = s.wrapT == TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT;
    tex_out.nearest = s.magFilter == TINYGLTF_TEXTURE_FILTER_NEAREST;
    tex_out.mipmaps = s.minFilter != TINYGLTF_TEXTURE_FILTER_NEAREST && s.minFilter != TINYGLTF_TEXTURE_FILTER_LINEAR;
  }
  *out_index = static_cast<int>(this->out.textures.size());
  this->out.textures.push_back(std::move(tex_out));
  texture_map[gltf_texture] = *out_index;
  return Status::ok();
}

Status Loader::load_materials() {
  for (std::size_t i = 0; i < model.materials.size(); ++i) {
    const tinygltf::Material& m = model.materials[i];
    SceneMaterial mat;
    mat.name = m.name.empty() ? "material " + std::to_string(i) : m.name;
    const auto& pbr = m.pbrMetallicRoughness;
    if (pbr.baseColorFactor.size() == 4) {
      mat.base_color_factor = glm::vec4(pbr.baseColorFactor[0], pbr.baseColorFactor[1], pbr.baseColorFactor[2],
                                        pbr.baseColorFactor[3]);
    }
    if (pbr.baseColorTexture.index >= 0) {
      if (Status s = load_texture(pbr.baseColorTexture.index, &mat.base_color_texture); !s) return s;
      mat.base_color_texcoord = pbr.baseColorTexture.texCoord;
    }
    // KHR_texture_transform: uv' = T(offset) R(rotation) S(scale) uv, baked into the texture coordinates.
    glm::mat3 uvm(1.0f);
    auto tt = pbr.baseColorTexture.extensions.find("KHR_texture_transform");
    if (tt != pbr.baseColorTexture.extensions.end() && tt->second.IsObject()) {
      const tinygltf::Value& v = tt->second;
      auto vec2 = [&](const char* key, glm::vec2 def) {
        if (!v.Has(key) || !v.Get(key).IsArray() || v.Get(key).ArrayLen() != 2) return def;
        return glm::vec2(v.Get(key).Get(0).GetNumberAsDouble(), v.Get(key).Get(1).GetNumberAsDouble());
      };
      const glm::vec2 offset = vec2("offset", glm::vec2(0.0f)), scl = vec2("scale", glm::vec2(1.0f));
      const float rot = v.Has("rotation") ? static_cast<float>(v.Get("rotation").GetNumberAsDouble()) : 0.0f;
      const float c = std::cos(rot), sn = std::sin(rot);
      // Columns, as the extension's GLSL: rotation = mat3(cos, sin, 0, -sin, cos, 0, 0, 0, 1).
      uvm = glm::mat3(glm::vec3(c * scl.x, sn * scl.x, 0.0f), glm::vec3(-sn * scl.y, c * scl.y, 0.0f),
                      glm::vec3(offset, 1.0f));
      if (v.Has("texCoord")) mat.base_color_texcoord = v.Get("texCoord").GetNumberAsInt();
    }
    uv_transform.push_back(uvm);
    mat.metallic = static_cast<float>(pbr.metallicFactor);
    mat.roughness = static_cast<float>(pbr.roughnessFactor);
    if (m.emissiveFactor.size() == 3) mat.emissive = glm::vec3(m.emissiveFactor[0], m.emissiveFactor[1], m.emissiveFactor[2]);
    auto strength = m.extensions.find("KHR_materials_emissive_strength");
    if (strength != m.extensions.end() && strength->second.Has("emissiveStrength")) {
      mat.emissive *= static_cast<float>(strength->second.Get("emissiveStrength").GetNumberAsDouble());
    }
    if (m.alphaMode == "MASK") mat.alpha_mode = SceneMaterial::AlphaMode::Mask;
    else if (m.alphaMode == "BLEND") mat.alpha_mode = SceneMaterial::AlphaMode::Blend;
    mat.alpha_cutoff = static_cast<float>(m.alphaCutoff);
    mat.double_sided = m.doubleSided;
    out.materials.push_back(std::move(mat));
  }
  return Status::ok();
}

namespace {

// Indices (or 0..n-1), then strips and fans to a triangle list (glTF 2.0 section 3.7.2.1).
Status triangle_list(const tinygltf::Model& model, const tinygltf::Primitive& prim, int mode, std::size_t n,
                     const std::string& file, const std::string& what, std::vector<std::string>& warnings,
                     std::vector<std::uint32_t>& out) {
  std::vector<std::uint32_t> idx;
  if (prim.indices >= 0) {
    if (Status s = read_uints(model, prim.indices, 1, file, "indices of " + what, idx); !s) return s;
    for (std::uint32_t i : idx) {
      if (i >= n) {
        return Error::input(file, "indices of " + what + ": index " + std::to_string(i) +
                                      " is out of range (the primitive has " + std::to_string(n) + " vertices)");
      }
    }
  } else {
    idx.resize(n);
    std::iota(idx.begin(), idx.end(), 0u);
  }
  if (mode == TINYGLTF_MODE_TRIANGLES) {
    if (idx.size() % 3 != 0) {
      warnings.push_back(what + ": " + std::to_string(idx.size() % 3) + " trailing indices ignored");
      idx.resize(idx.size() - idx.size() % 3);
    }
    out = std::move(idx);
  } else if (idx.size() >= 3) {
    for (std::size_t i = 0; i + 2 < idx.size(); ++i) {
      if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
        // p_i = {v_i, v_{i+(1+i%2)}, v_{i+(2-i%2)}}: keeps every triangle's winding.
        out.insert(out.end(), {idx[i], idx[i + 1 + i % 2], idx[i + 2 - i % 2]});
      } else {
        out.insert(out.end(), {idx[i + 1], idx[i + 2], idx[0]});
      }
    }
  }
  return Status::ok();
}

// Skin influences: JOINTS_n / WEIGHTS_n pairs, 4 influences each, renormalised to sum 1 (section 3.7.3.3;
// exporters round them). *max_joint receives the largest joint index used + 1.
Status read_influences(const tinygltf::Model& model, const tinygltf::Primitive& prim, std::size_t n,
                       const std::string& file, const std::string& what, PrimitiveData& data,
                       std::uint32_t* max_joint) {
  std::vector<float> f;
  std::uint32_t max_j = 0;
  for (int s = 0;; ++s) {
    auto jt = prim.attributes.find("JOINTS_" + std::to_string(s));
    auto wt = prim.attributes.find("WEIGHTS_" + std::to_string(s));
    if (jt == prim.attributes.end() || wt == prim.attributes.end()) break;
    std::vector<std::uint32_t> j;
    if (Status st = read_uints(model, jt->second, 4, file, jt->first + " of " + what, j); !st) return st;
    if (Status st = read_floats(model, wt->second, 4, file, wt->first + " of " + what, f); !st) return st;
    if (j.size() != 4 * n || f.size() != 4 * n) {
      return Error::input(file, jt->first + "/" + wt->first + " of " + what + " do not have one element per vertex");
    }
    const int k = data.influences;
    data.influences += 4;
    std::vector<std::uint16_t> nj(n * static_cast<std::size_t>(data.influences));
    std::vector<float> nw(nj.size());
    for (std::size_t v = 0; v < n; ++v) {
      for (int c = 0; c < k; ++c) {
        nj[v * data.influences + c] = data.joints[v * k + c];
        nw[v * data.influences + c] = data.weights[v * k + c];
      }
      for (int c = 0; c < 4; ++c) {
        const float w = f[4 * v + c];
        const std::uint32_t jj = w > 0.0f ? j[4 * v + c] : 0u;  // zero-weight slots may hold any index
        if (jj > 65535u) return Error::input(file, jt->first + " of " + what + ": joint index too large");
        max_j = std::max(max_j, jj + 1);
        nj[v * data.influences + k + c] = static_cast<std::uint16_t>(jj);
        nw[v * data.influences + k + c] = std::isfinite(w) ? std::max(w, 0.0f) : 0.0f;
      }
    }
    data.joints = std::move(nj);
    data.weights = std::move(nw);
  }
  normalise_skin_weights(data, n);
  *max_joint = max_j;
  return Status::ok();
}

}  // namespace

Status Loader::load_primitive(const tinygltf::Primitive& prim, const std::string& what, bool skinned_use, int* index) {
  *index = -1;
  const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
  if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP && mode != TINYGLTF_MODE_TRIANGLE_FAN) {
    out.warnings.push_back(what + " draws points or lines (mode " + std::to_string(mode) + "): skipped");
    return Status::ok();
  }
  auto pos_it = prim.attributes.find("POSITION");
  if (pos_it == prim.attributes.end()) {
    out.warnings.push_back(what + " has no POSITION: skipped");
    return Status::ok();
  }
  if (prim.material >= static_cast<int>(model.materials.size())) {
    return Error::input(file, what + " names material " + std::to_string(prim.material) + ", which does not exist");
  }
  ScenePrimitive sp;
  PrimitiveData data;
  std::vector<float> f;
  if (Status s = read_floats(model, pos_it->second, 3, file, "POSITION of " + what, f); !s) return s;
  const std::size_t n = f.size() / 3;
  if (!std::all_of(f.begin(), f.end(), [](float x) { return std::isfinite(x); })) {
    return Error::input(file, "POSITION of " + what + " holds NaN or infinite values");
  }
  sp.positions = to_vec3(f);
  bool has = false;
  // Not-finite normals and texture coordinates are refused here, naming the accessor: normalising would hide
  // NaN normals, and coordinates past kMaxTexcoord overflow the texture lookup into NaN pixels.
  auto accessor_of = [&](const std::string& name) { return std::to_string(prim.attributes.at(name)); };
  auto all_finite = [&] { return std::all_of(f.begin(), f.end(), [](float x) { return std::isfinite(x); }); };
  if (Status s = read_attribute(model, prim.attributes, "NORMAL", 3, n, file, what, f, &has); !s) return s;
  if (has && !all_finite())
    return Error::input(file, "NORMAL of " + what + " (accessor " + accessor_of("NORMAL") + ") holds NaN or infinite values");
  if (has) sp.normals = to_vec3(f);
  // The texture coordinate set the base colour texture reads (TEXCOORD_0 unless the material says otherwise).
  int set = 0;
  if (prim.material >= 0) set = std::max(0, out.materials[static_cast<std::size_t>(prim.material)].base_color_texcoord);
  if (Status s = read_attribute(model, prim.attributes, "TEXCOORD_" + std::to_string(set), 2, n, file, what, f, &has); !s) return s;
  if (has) {
    sp.texcoords.resize(n);
    for (std::size_t i = 0; i < n; ++i) sp.texcoords[i] = glm::vec2(f[2 * i], f[2 * i + 1]);
    if (prim.material >= 0 && uv_transform[static_cast<std::size_t>(prim.material)] != glm::mat3(1.0f)) {
      const glm::mat3& t = uv_transform[static_cast<std::size_t>(prim.material)];
      for (auto& uv : sp.texcoords) uv = glm::vec2(t * glm::vec3(uv, 1.0f));
    }
    const std::string name = "TEXCOORD_" + std::to_string(set);
    if (!std::all_of(sp.texcoords.begin(), sp.texcoords.end(), texcoord_in_range))
      return Error::input(file, name + " of " + what + " (accessor " + accessor_of(name) + ") holds NaN, infinite or "
                                    "huge values (beyond +-1e6, after KHR_texture_transform)");
  }
  if (Status s = triangle_list(model, prim, mode, n, file, what, out.warnings, sp.indices); !s) return s;
  if (sp.indices.empty()) {
    out.warnings.push_back(what + " has no triangles: skipped");
    return Status::ok();
  }
  std::uint32_t max_j = 0;
  if (Status s = read_influences(model, prim, n, file, what, data, &max_j); !s) return s;
  if (data.influences > 0) sp.skinned = skinned_use;

  // Morph targets: POSITION / NORMAL displacements (section 3.7.2.2).
  for (std::size_t t = 0; t < prim.targets.size(); ++t) {
    const std::string tw = "morph target " + std::to_string(t) + " of " + what;
    std::vector<glm::vec3> tp(n, glm::vec3(0.0f)), tn;
    if (Status s = read_attribute(model, prim.targets[t], "POSITION", 3, n, file, tw, f, &has); !s) return s;
    if (has) tp = to_vec3(f);
    if (Status s = read_attribute(model, prim.targets[t], "NORMAL", 3, n, file, tw, f, &has); !s) return s;
    if (has) tn = to_vec3(f);
    data.target_positions.push_back(std::move(tp));
    data.target_normals.push_back(std::move(tn));
  }
  sp.morphed = !data.target_positions.empty();

  if (sp.normals.empty()) {
    make_flat_normals(sp, data);
  } else {
    normalise_normals(sp.normals);
  }
  compute_local_bounds(sp, data);
  if (prim.material < 0) {
    if (default_material < 0) default_material = add_default_material(out.materials);
    sp.material = default_material;
  } else {
    sp.material = prim.material;
  }
  *index = static_cast<int>(out.primitives.size());
  max_joint.push_back(max_j);
  out.primitives.push_back(std::move(sp));
  out.primitive_data.push_back(std::move(data));
  return Status::ok();
}

Status Loader::load_mesh(int mesh_index, bool skinned_use) {
  const tinygltf::Mesh& mesh = model.meshes[static_cast<std::size_t>(mesh_index)];
  auto& list = mesh_primitives[static_cast<std::size_t>(mesh_index)];
  int targets = 0;
  for (std::size_t pi = 0; pi < mesh.primitives.size(); ++pi) {
    const std::string what = "primitive " + std::to_string(pi) + " of mesh " + quoted_or_index(mesh.name, mesh_index);
    int index = -1;
    if (Status s = load_primitive(mesh.primitives[pi], what, skinned_use, &index); !s) return s;
    list.push_back(index);
    if (index >= 0) {
      targets = std::max(targets, static_cast<int>(out.primitive_data[static_cast<std::size_t>(index)].target_positions.size()));
    }
  }
  mesh_targets[static_cast<std::size_t>(mesh_index)] = targets;
  return Status::ok();
}

}  // namespace temporal::scene_detail
