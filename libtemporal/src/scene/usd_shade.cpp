// UsdShade to SceneMaterial: material bindings (material:binding:preview, else material:binding, on the
// gprim or its nearest ancestor; GeomSubsets with their own binding), UsdPreviewSurface inputs (diffuseColor,
// opacity and opacityThreshold, metallic, roughness, emissiveColor) and UsdUVTexture for the diffuse colour
// (read with stb_image, the reader tinygltf uses for glTF's images, so that the scene stage needs no
// image library; scale multiplies it like glTF's base colour factor), UsdPrimvarReader_float3 of
// displayColor. Materials are created in the order of their Material prims so that ids are stable.
#include "usd_convert.h"

#include <stb_image.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>

namespace temporal::scene_detail::usd_detail {
namespace {

const Prim* bound_material(const usd::Stage& stage, const Prim& gprim, bool inherit) {
  for (const Prim* q = &gprim; q && q->path != "/"; q = inherit ? q->parent : nullptr) {
    for (const char* rel : {"material:binding:preview", "material:binding"}) {
      const auto targets = q->targets(rel);
      if (targets.empty()) continue;
      const Prim* m = stage.prim_at(targets.front());
      return m && m->type_name == "Material" ? m : nullptr;
    }
  }
  return nullptr;
}

// The prim and output a connected input reads ("/mat/tex.outputs:rgb" -> tex, "outputs:rgb"), following
// NodeGraph outputs to the shader behind them.
const Prim* source(const usd::Stage& stage, const Prim& prim, const std::string& input, std::string* output) {
  const Prim* at = &prim;
  std::string name = input;
  for (int hop = 0; hop < 8; ++hop) {
    const auto c = at->connections(name);
    if (c.empty()) return hop == 0 ? nullptr : at;
    const std::size_t dot = c.front().rfind('.');
    if (dot == std::string::npos) return nullptr;
    const Prim* src = stage.prim_at(c.front().substr(0, dot));
    if (!src) return nullptr;
    *output = c.front().substr(dot + 1);
    if (src->type_name != "NodeGraph" && src->type_name != "Material") return src;
    at = src;
    name = *output;
  }
  return nullptr;
}

// The UsdPreviewSurface shader behind a Material's outputs:surface.
const Prim* surface_shader(const usd::Stage& stage, const Converter& cv, const Prim& material) {
  std::string output;
  const Prim* s = source(stage, material, "outputs:surface", &output);
  if (!s || cv.token(*s, "info:id").value_or("") != "UsdPreviewSurface") return nullptr;
  return s;
}

bool reads_display_color(const usd::Stage& stage, const Converter& cv, const Prim& material) {
  const Prim* surface = surface_shader(stage, cv, material);
  std::string output;
  const Prim* src = surface ? source(stage, *surface, "inputs:diffuseColor", &output) : nullptr;
  return src && cv.token(*src, "info:id").value_or("").rfind("UsdPrimvarReader", 0) == 0 &&
         cv.token(*src, "inputs:varname").value_or("") == "displayColor";
}

std::string format_color(glm::vec3 c) {
  char buf[80];
  std::snprintf(buf, sizeof buf, "%.9g,%.9g,%.9g", c.r, c.g, c.b);
  return buf;
}

}  // namespace

std::string Converter::material_key(const Prim& gprim, const Prim& mesh, bool double_sided, const double* color) {
  MaterialRecipe r;
  const Prim* m = bound_material(stage, gprim, &gprim == &mesh);
  if (!m && &gprim != &mesh) m = bound_material(stage, mesh, true);
  r.material = m ? m->path : "";
  r.double_sided = double_sided;
  if (!m || reads_display_color(stage, *this, *m)) {
    const std::vector<double>* c = numbers(mesh, "primvars:displayColor", 3);
    if (color) {
      r.has_color = true;
      r.display_color = glm::vec3(float(color[0]), float(color[1]), float(color[2]));
    } else if (c && !c->empty()) {
      r.has_color = true;
      r.display_color = glm::vec3(float((*c)[0]), float((*c)[1]), float((*c)[2]));
      if (c->size() > 3)
        warn_once("dc:" + mesh.path, where(mesh) + ": primvars:displayColor of " + mesh.path +
                                         " varies over the mesh; its first value colours the whole mesh");
    }
  }
  const std::string key = r.material + "|" + (double_sided ? "2" : "1") + "|" + (r.has_color ? format_color(r.display_color) : "");
  if (recipes.emplace(key, r).second) key_order.push_back(key);
  return key;
}

// Faces grouped by their uniform displayColor (at most 64 colours), each group its own material: for meshes
// coloured per face whose material reads displayColor (or that have no material).
bool Converter::color_slots(MeshJob& job, bool double_sided) {
  const Prim& mesh = *job.prim;
  const Value* interp = mesh.property_meta("primvars:displayColor", "interpolation");
  if (!interp || interp->text.size() != 1 || interp->text[0] != "uniform") return false;
  const Prim* m = bound_material(stage, mesh, true);
  if (m && !reads_display_color(stage, *this, *m)) return false;
  const std::vector<double>* colors = numbers(mesh, "primvars:displayColor", 3);
  const std::vector<double>* counts = numbers(mesh, "faceVertexCounts", 1);
  if (!colors || !counts || colors->size() != 3 * counts->size() || value(mesh, "primvars:displayColor:indices")) return false;
  std::vector<std::array<double, 3>> distinct;
  std::vector<int> face_slot(counts->size());
  for (std::size_t f = 0; f < counts->size(); ++f) {
    const std::array<double, 3> c = {(*colors)[3 * f], (*colors)[3 * f + 1], (*colors)[3 * f + 2]};
    auto it = std::find(distinct.begin(), distinct.end(), c);
    face_slot[f] = int(it - distinct.begin());
    if (it == distinct.end()) distinct.push_back(c);
  }
  if (distinct.size() > 64) return false;
  job.material_keys.push_back(material_key(mesh, mesh, double_sided, distinct[0].data()));
  job.slot_faces.assign(distinct.size(), {});
  for (std::size_t f = 0; f < face_slot.size(); ++f) job.slot_faces[std::size_t(face_slot[f])].push_back(int(f));
  for (const auto& c : distinct) job.material_keys.push_back(material_key(mesh, mesh, double_sided, c.data()));
  return true;
}

Status Converter::material_slots(MeshJob& job) {
  const Prim& mesh = *job.prim;
  const bool double_sided = number(mesh, "doubleSided").value_or(0.0) != 0.0;
  if (color_slots(job, double_sided)) return {};
  job.material_keys.push_back(material_key(mesh, mesh, double_sided));
  for (const auto& c : mesh.children) {
    const Prim& subset = *c;
    if (subset.type_name != "GeomSubset" || !subset.active || !subset.defined()) continue;
    if (!bound_material(stage, subset, false)) continue;
    if (token(subset, "elementType").value_or("face") != "face") continue;
    const std::vector<double>* faces = numbers(subset, "indices", 1);
    if (!faces) continue;
    job.material_keys.push_back(material_key(subset, mesh, double_sided));
    std::vector<int> f(faces->begin(), faces->end());
    job.slot_faces.push_back(std::move(f));
  }
  return {};
}

namespace {

// An image file as RGBA8, top row first (stb_image: PNG, JPEG, TGA, BMP, PSD, GIF, HDR, PIC, PNM). Colours as
// stored: stb_image never premultiplies by alpha (glTF's images are not premultiplied either). Grey expands to
// R = G = B, grey + alpha keeps its alpha, three channels get alpha 255.
Status read_image(const std::string& file, const std::string& where, SceneTexture& tex) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) return Error::input(where, "the texture '" + file + "' does not exist");
  int width = 0, height = 0, channels = 0;
  if (!stbi_info(file.c_str(), &width, &height, &channels))
    return Error::input(where, "cannot read the texture '" + file + "': " + stbi_failure_reason() +
                                   " (textures are read with stb_image: PNG, JPEG, TGA, BMP, PSD, GIF, HDR, PNM; convert "
                                   "EXR or TIFF textures to PNG, e.g. with oiiotool)");
  if (width <= 0 || height <= 0 || width > 16384 || height > 16384 || channels < 1)
    return Error::input(where, "the texture '" + file + "' has an unsupported size or no channels");
  // "auto" colour space: 8-bit images are sRGB-encoded, 16-bit and float images linear (UsdUVTexture).
  const bool high_precision = stbi_is_hdr(file.c_str()) || stbi_is_16_bit(file.c_str());
  stbi_uc* data = stbi_load(file.c_str(), &width, &height, &channels, 4);
  if (!data) return Error::input(where, "cannot decode the texture '" + file + "': " + stbi_failure_reason());
  const std::size_t bytes = std::size_t(width) * std::size_t(height) * 4;
  tex.width = width;
  tex.height = height;
  tex.rgba8.assign(data, data + bytes);
  stbi_image_free(data);
  tex.srgb = !high_precision;
  return {};
}

}  // namespace

Status Converter::create_materials() {
  std::vector<std::string> order;
  for (const std::string& m : material_prims)
    for (const std::string& k : key_order)
      if (recipes[k].material == m) {
        order.push_back(k);
        break;
      }
  for (const std::string& k : key_order)
    if (std::find(order.begin(), order.end(), k) == order.end()) order.push_back(k);
  for (const std::string& key : order) {
    const MaterialRecipe& r = recipes[key];
    SceneMaterial m;
    std::string uv = "st";
    const Prim* prim = r.material.empty() ? nullptr : stage.prim_at(r.material);
    if (!prim) {
      m.name = r.has_color ? "displayColor" : "default";
      m.base_color_factor = r.has_color ? glm::vec4(r.display_color, 1.0f) : glm::vec4(0.8f, 0.8f, 0.8f, 1.0f);
    } else {
      m.name = prim->name;
      if (Status s = preview_surface(*prim, r, m, uv); !s) return s;
    }
    m.double_sided = r.double_sided;
    material_index[key] = static_cast<int>(out.materials.size());
    out.materials.push_back(std::move(m));
    uv_primvar.push_back(uv);
  }
  return {};
}

Status Converter::preview_surface(const Prim& material, const MaterialRecipe& r, SceneMaterial& m, std::string& uv) {
  const Prim* surface = surface_shader(stage, *this, material);
  if (!surface) {
    warn_once("nosurf:" + material.path, where(material) + ": material " + material.path +
                                             " has no UsdPreviewSurface on outputs:surface: drawn grey");
    m.base_color_factor = glm::vec4(0.18f, 0.18f, 0.18f, 1.0f);
    return {};
  }
  auto input = [&](const char* name, double fallback) { return number(*surface, std::string("inputs:") + name).value_or(fallback); };
  const auto diffuse = numbers_or(*surface, "inputs:diffuseColor", 3, {0.18, 0.18, 0.18});
  m.base_color_factor = glm::vec4(float(diffuse[0]), float(diffuse[1]), float(diffuse[2]), float(input("opacity", 1.0)));
  m.metallic = float(input("metallic", 0.0));
  m.roughness = float(input("roughness", 0.5));
  const auto emissive = numbers_or(*surface, "inputs:emissiveColor", 3, {0.0, 0.0, 0.0});
  m.emissive = glm::vec3(float(emissive[0]), float(emissive[1]), float(emissive[2]));
  for (const char* unsupported : {"inputs:metallic", "inputs:roughness", "inputs:normal", "inputs:emissiveColor", "inputs:occlusion"}) {
    std::string output;
    if (source(stage, *surface, unsupported, &output))
      warn_once(std::string("tex:") + unsupported, std::string("textures on UsdPreviewSurface ") + unsupported +
                                                       " are not used (only diffuseColor and opacity), first in " + material.path);
  }
  std::string output;
  const Prim* src = source(stage, *surface, "inputs:diffuseColor", &output);
  const std::string id = src ? token(*src, "info:id").value_or("") : "";
  if (src && id == "UsdUVTexture") {
    if (Status s = uv_texture(*src, m, uv); !s) return s;
  } else if (src && id.rfind("UsdPrimvarReader", 0) == 0) {
    const glm::vec3 fallback = r.has_color ? r.display_color : glm::vec3(float(diffuse[0]), float(diffuse[1]), float(diffuse[2]));
    m.base_color_factor = glm::vec4(fallback, m.base_color_factor.a);
  }
  std::string alpha_output;
  const Prim* alpha = source(stage, *surface, "inputs:opacity", &alpha_output);
  const bool textured_alpha = alpha && m.base_color_texture >= 0 && alpha == src && alpha_output == "outputs:a";
  const double threshold = input("opacityThreshold", 0.0);
  if (threshold > 0.0) {
    m.alpha_mode = SceneMaterial::AlphaMode::Mask;
    m.alpha_cutoff = float(threshold);
  } else if (textured_alpha || m.base_color_factor.a < 1.0f) {
    m.alpha_mode = SceneMaterial::AlphaMode::Blend;
  }
  if (!textured_alpha && m.base_color_texture >= 0 && m.alpha_mode != SceneMaterial::AlphaMode::Opaque) {
    // Opacity from a value while the diffuse texture has alpha: the texture's alpha must not cut.
    m.alpha_mode = m.base_color_factor.a < 1.0f ? SceneMaterial::AlphaMode::Blend : SceneMaterial::AlphaMode::Opaque;
  }
  return {};
}

Status Converter::uv_texture(const Prim& tex, SceneMaterial& m, std::string& uv) {
  auto file = value(tex, "inputs:file");
  if (!file || file->kind != Value::Kind::Asset || file->resolved.empty() || file->resolved[0].empty()) {
    warn(where(tex) + ": UsdUVTexture " + tex.path + " has no inputs:file: drawn without it");
    return {};
  }
  const std::string path = file->resolved[0];
  if (path.find("<UDIM>") != std::string::npos) {
    warn_once("udim", where(tex) + ": UDIM textures are not supported: " + tex.path + " drawn without its texture");
    return {};
  }
  const auto scale = numbers_or(tex, "inputs:scale", 4, {1.0, 1.0, 1.0, 1.0});
  const auto bias = numbers_or(tex, "inputs:bias", 4, {0.0, 0.0, 0.0, 0.0});
  if (std::any_of(bias.begin(), bias.end(), [](double b) { return b != 0.0; }))
    warn_once("bias:" + tex.path, where(tex) + ": inputs:bias of UsdUVTexture is not applied");
  m.base_color_factor = glm::vec4(float(scale[0]), float(scale[1]), float(scale[2]), float(scale[3]) * m.base_color_factor.a);
  const std::string wrap_s = token(tex, "inputs:wrapS").value_or("useMetadata");
  const std::string wrap_t = token(tex, "inputs:wrapT").value_or("useMetadata");
  const std::string space = token(tex, "inputs:sourceColorSpace").value_or("auto");
  std::string output;
  if (const Prim* reader = source(stage, tex, "inputs:st", &output)) {
    if (auto name = token(*reader, "inputs:varname")) uv = *name;
  }
  const std::string key = path + "|" + wrap_s + "|" + wrap_t + "|" + space;
  auto found = texture_index.find(key);
  if (found != texture_index.end()) {
    m.base_color_texture = found->second;
    return {};
  }
  SceneTexture t;
  out.inputs.push_back(path);
  if (Status s = read_image(path, where(tex), t); !s) return s;
  if (space == "raw") t.srgb = false;
  if (space == "sRGB") t.srgb = true;
  auto wrap = [&](const std::string& w, bool& repeat, bool& mirror) {
    // useMetadata (no metadata is read) and black are taken as repeat and clamp.
    repeat = w == "repeat" || w == "useMetadata";
    mirror = w == "mirror";
    if (w == "black") warn_once("black", "UsdUVTexture wrap mode 'black' is drawn as 'clamp'");
  };
  wrap(wrap_s, t.repeat_s, t.mirror_s);
  wrap(wrap_t, t.repeat_t, t.mirror_t);
  m.base_color_texture = static_cast<int>(out.textures.size());
  texture_index[key] = m.base_color_texture;
  out.textures.push_back(std::move(t));
  return {};
}

}  // namespace temporal::scene_detail::usd_detail
