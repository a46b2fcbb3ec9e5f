// The text USD reader's entry point and its traversal: composes the stage, walks the drawn prims (active,
// defined, not abstract, visible, purpose default or render) and turns UsdGeomXformable transform stacks,
// cameras and UsdLux lights into nodes; meshes, materials and skeletons are converted by usd_mesh.cpp,
// usd_shade.cpp and usd_skel.cpp. Time: stage time code tc is (tc - startTimeCode) / timeCodesPerSecond
// seconds; held values between samples interpolate linearly (quaternions by slerp), as USD specifies.
#include "usd_convert.h"
#include "usd_reader.h"

#include <glm/gtc/type_ptr.hpp>

#include <algorithm>
#include <cmath>

namespace temporal::scene_detail {
namespace usd_detail {

std::string where(const Prim& prim) {
  if (prim.sites.empty()) return prim.path;
  const Site& s = prim.sites.front();
  return s.layer->path + ":" + std::to_string(s.spec->line) + ":" + std::to_string(s.spec->column);
}

std::string where(const Site& site, const PropertySpec& property) {
  return site.layer->path + ":" + std::to_string(property.line) + ":" + std::to_string(property.column);
}

void Converter::warn(const std::string& message) { out.warnings.push_back(message); }

void Converter::warn_once(const std::string& key, const std::string& message) {
  if (std::find(warned.begin(), warned.end(), key) != warned.end()) return;
  warned.push_back(key);
  out.warnings.push_back(message);
}

const Value* Converter::value(const Prim& prim, std::string_view name) const {
  const PropertySpec* p = prim.attribute(name);
  if (!p) return nullptr;
  for (const auto& [t, v] : p->time_samples)
    if (!v.is_none()) return &v;
  if (p->has_default && !p->default_value.is_none()) return &p->default_value;
  return nullptr;
}

std::optional<double> Converter::number(const Prim& prim, std::string_view name) const {
  const Value* v = value(prim, name);
  if (!v || v->kind != Value::Kind::Number || v->numbers.size() != 1) return std::nullopt;
  return v->numbers[0];
}

std::optional<std::string> Converter::token(const Prim& prim, std::string_view name) const {
  const Value* v = value(prim, name);
  if (!v || (v->kind != Value::Kind::String && v->kind != Value::Kind::Asset) || v->text.size() != 1) return std::nullopt;
  return v->text[0];
}

const std::vector<double>* Converter::numbers(const Prim& prim, std::string_view name, int tuple) const {
  const Value* v = value(prim, name);
  if (!v || v->kind != Value::Kind::Number || v->tuple != tuple) return nullptr;
  return &v->numbers;
}

std::vector<double> Converter::numbers_or(const Prim& prim, std::string_view name, int tuple,
                                          std::vector<double> fallback) const {
  const std::vector<double>* v = numbers(prim, name, tuple);
  return v ? *v : fallback;
}

float Converter::seconds(const Site& site, double layer_time_code) const {
  const double tc = site.offset.offset + site.offset.scale * layer_time_code;
  return static_cast<float>((tc - start_tc) / tcps);
}

Expected<int> Converter::sampler(const Prim& prim, std::string_view name, int components, Interpolation interpolation,
                                 void (*convert)(const double*, float*, int)) {
  const Site* site = nullptr;
  const PropertySpec* p = prim.attribute(name, &site);
  if (!p || p->time_samples.size() < 2) return -1;
  std::vector<std::pair<float, std::size_t>> keys;
  for (std::size_t k = 0; k < p->time_samples.size(); ++k) {
    const auto& [t, v] = p->time_samples[k];
    if (v.is_none()) {
      warn_once(where(*site, *p) + "block", where(*site, *p) + ": blocked (None) time samples of '" + std::string(name) +
                                                  "' are ignored (the neighbouring samples are interpolated)");
      continue;
    }
    if (v.kind != Value::Kind::Number || v.numbers.size() != std::size_t(components)) {
      return Error::input(where(*site, *p), "the time sample at " + std::to_string(t) + " of '" + std::string(name) + "' holds " +
                                                std::to_string(v.numbers.size()) + " numbers, expected " +
                                                std::to_string(components));
    }
    keys.emplace_back(seconds(*site, t), k);
    const double tc = site->offset.offset + site->offset.scale * t;
    last_tc = sampled ? std::max(last_tc, tc) : tc;
    sampled = true;
  }
  if (keys.size() < 2) return -1;
  auto earlier = [](const auto& a, const auto& b) { return a.first < b.first; };
  if (!std::is_sorted(keys.begin(), keys.end(), earlier)) std::stable_sort(keys.begin(), keys.end(), earlier);  // negative scale
  Sampler s;
  s.components = components;
  s.interpolation = interpolation;
  s.values.resize(keys.size() * std::size_t(components));
  for (std::size_t k = 0; k < keys.size(); ++k) {
    if (!s.times.empty() && !(keys[k].first > s.times.back())) continue;  // equal after the conversion to float
    const double* in = p->time_samples[keys[k].second].second.numbers.data();
    float* o = s.values.data() + s.times.size() * std::size_t(components);
    if (convert) {
      convert(in, o, components);
    } else {
      for (int c = 0; c < components; ++c) o[c] = static_cast<float>(in[c]);
    }
    s.times.push_back(keys[k].first);
  }
  s.values.resize(s.times.size() * std::size_t(components));
  if (!std::all_of(s.values.begin(), s.values.end(), [](float x) { return std::isfinite(x); }))
    return Error::input(where(*site, *p), "the time samples of '" + std::string(name) + "' hold NaN or infinite values");
  out.samplers.push_back(std::move(s));
  return static_cast<int>(out.samplers.size()) - 1;
}

int Converter::add_node(const std::string& name, int parent) {
  Node n;
  n.name = name;
  n.parent = parent;
  out.nodes.push_back(std::move(n));
  const int index = static_cast<int>(out.nodes.size()) - 1;
  out.order.push_back(index);
  return index;
}

namespace {

using Kind = XformOp::Kind;

std::optional<Kind> op_kind(std::string_view type) {
  static const std::pair<const char*, Kind> kinds[] = {
      {"translate", Kind::Translate}, {"scale", Kind::Scale},         {"rotateX", Kind::RotateX},
      {"rotateY", Kind::RotateY},     {"rotateZ", Kind::RotateZ},     {"rotateXYZ", Kind::RotateXYZ},
      {"rotateXZY", Kind::RotateXZY}, {"rotateYXZ", Kind::RotateYXZ}, {"rotateYZX", Kind::RotateYZX},
      {"rotateZXY", Kind::RotateZXY}, {"rotateZYX", Kind::RotateZYX}, {"orient", Kind::Orient},
      {"transform", Kind::Transform}};
  for (const auto& [n, k] : kinds)
    if (type == n) return k;
  return std::nullopt;
}

int op_components(Kind k) {
  switch (k) {
    case Kind::RotateX: case Kind::RotateY: case Kind::RotateZ: return 1;
    case Kind::Orient: return 4;
    case Kind::Transform: return 16;
    default: return 3;
  }
}

// USD quaternions are (real, i, j, k); the description stores (x, y, z, w).
void quat_to_xyzw(const double* in, float* out, int) {
  out[0] = static_cast<float>(in[1]);
  out[1] = static_cast<float>(in[2]);
  out[2] = static_cast<float>(in[3]);
  out[3] = static_cast<float>(in[0]);
}

}  // namespace

// The node of an xformable prim: its own when it has transform ops (or `force`), else its parent's.
Expected<int> Converter::transform_node(const Prim& prim, int parent_node, bool force) {
  const Value* order = value(prim, "xformOpOrder");
  const bool has_ops = order && order->kind == Value::Kind::String && !order->text.empty();
  if (!has_ops) return force || parent_node < 0 ? add_node(prim.name, parent_node) : parent_node;
  std::vector<XformOp> ops;
  std::vector<std::string> names;
  bool reset = false, invert = false;
  for (std::size_t k = 0; k < order->text.size(); ++k) {
    std::string name = order->text[k];
    if (name == "!resetXformStack!") {
      if (k != 0) warn(where(prim) + ": !resetXformStack! is only meaningful first in xformOpOrder: ignored");
      reset = reset || k == 0;
      continue;
    }
    XformOp op;
    if (name.rfind("!invert!", 0) == 0) {
      op.inverse = invert = true;
      name = name.substr(8);
    }
    const std::size_t colon = name.find(':', 8);
    auto kind = name.rfind("xformOp:", 0) == 0 ? op_kind(std::string_view(name).substr(8, colon == std::string::npos ? std::string::npos : colon - 8))
                                               : std::nullopt;
    if (!kind) return Error::input(where(prim), "xformOpOrder names '" + name + "', which is not a transform op (xformOp:translate, rotateXYZ, orient, scale, transform ...)");
    op.kind = *kind;
    const int n = op_components(op.kind);
    const Value* v = value(prim, name);
    if (!v || v->kind != Value::Kind::Number || v->numbers.size() != std::size_t(n))
      return Error::input(where(prim), "xformOpOrder names '" + name + "', which prim " + prim.path +
                                           (v ? " authors with the wrong number of values" : " does not have"));
    if (op.kind == Kind::Orient) quat_to_xyzw(v->numbers.data(), op.value.data(), 4);
    else for (int c = 0; c < n; ++c) op.value[std::size_t(c)] = static_cast<float>(v->numbers[std::size_t(c)]);
    auto s = sampler(prim, name, n, Interpolation::Linear, op.kind == Kind::Orient ? quat_to_xyzw : nullptr);
    if (!s) return s.error();
    if (op.kind == Kind::Orient) {
      // A zero quaternion has no rotation (glm would silently normalise it to the identity): refused.
      auto usable = [](double x, double y, double z, double w) {
        const double len = std::sqrt(x * x + y * y + z * z + w * w);
        return std::isfinite(len) && len >= scene_detail::kMinRotationLength;
      };
      bool ok = usable(v->numbers[0], v->numbers[1], v->numbers[2], v->numbers[3]);
      if (*s >= 0) {
        const std::vector<float>& q = out.samplers[std::size_t(*s)].values;
        for (std::size_t j = 0; ok && j + 4 <= q.size(); j += 4) ok = usable(q[j], q[j + 1], q[j + 2], q[j + 3]);
      }
      if (!ok)
        return Error::input(where(prim), "'" + name + "' of prim " + prim.path +
                                             " is a quaternion of length 0 (or not finite): it has no rotation");
    }
    op.sampler = *s;
    ops.push_back(op);
    names.push_back(name);
  }
  const int node = add_node(prim.name, parent_node);
  Node& nd = out.nodes[std::size_t(node)];
  nd.reset_parent = reset;
  // translate / orient / scale stacks (what glTF's TRS is) take the TRS path, exactly as a glTF node.
  bool trs = !invert;
  int last = -1;
  for (const XformOp& op : ops) {
    const int rank = op.kind == Kind::Translate ? 0 : op.kind == Kind::Orient ? 1 : op.kind == Kind::Scale ? 2 : 9;
    trs = trs && rank <= 2 && rank > last;
    last = rank;
  }
  if (trs) {
    for (const XformOp& op : ops) {
      const float* v = op.value.data();
      TargetPath path = TargetPath::Translation;
      if (op.kind == Kind::Translate) {
        nd.translation = glm::vec3(v[0], v[1], v[2]);
      } else if (op.kind == Kind::Orient) {
        nd.rotation = glm::normalize(glm::quat(v[3], v[0], v[1], v[2]));
        path = TargetPath::Rotation;
      } else {
        nd.scale = glm::vec3(v[0], v[1], v[2]);
        path = TargetPath::Scale;
      }
      if (op.sampler >= 0) out.channels.push_back({node, path, op.sampler});
    }
  } else if (ops.size() == 1 && ops[0].kind == Kind::Transform && ops[0].sampler < 0 && !ops[0].inverse) {
    nd.matrix = glm::make_mat4(ops[0].value.data());  // USD's rows are glm's columns (row vs column vectors)
    nd.use_matrix = true;
  } else {
    nd.ops = std::move(ops);
  }
  return node;
}

namespace {

bool is_one_of(const std::string& t, std::initializer_list<const char*> names) {
  for (const char* n : names)
    if (t == n) return true;
  return false;
}

}  // namespace

// `drawn` is false below invisible prims and prims of purpose guide or proxy: nothing there is drawn or lit,
// but skeletons (which deform drawn meshes) and cameras are still read.
Status Converter::traverse(const Prim& parent, int parent_node, int depth, bool drawn) {
  if (depth > 256) return Error::input(where(parent), "prims nested more than 256 deep");
  for (const auto& c : parent.children) {
    const Prim& p = *c;
    if (!p.active || !p.defined()) continue;  // inactive, over-only or class prims are not drawn
    const std::string& type = p.type_name;
    if (type == "Material") {
      material_prims.push_back(p.path);
      continue;
    }
    if (is_one_of(type, {"Shader", "NodeGraph", "SkelAnimation", "BlendShape", "GeomSubset"})) continue;
    bool visible = drawn;
    if (auto vis = token(p, "visibility"); vis && *vis == "invisible") visible = false;
    if (const PropertySpec* v = p.attribute("visibility"); v && v->time_samples.size() > 1)
      warn_once(p.path + "vis", where(p) + ": animated visibility is not replayed (the value at the start is used)");
    if (auto purpose = token(p, "purpose"); purpose && *purpose != "default" && *purpose != "render") visible = false;
    const bool deformable = type == "Mesh" && (p.attribute("primvars:skel:jointIndices") || p.property("skel:blendShapes"));
    auto node = transform_node(p, parent_node, deformable || type == "Skeleton");
    if (!node) return node.error();
    if (type == "Mesh") {
      if (visible) meshes.push_back({&p, *node, {}, {}});
    } else if (type == "Camera") {
      if (Status s = camera(p, *node); !s) return s;
    } else if (type.size() > 5 && type.compare(type.size() - 5, 5, "Light") == 0) {
      if (visible)
        if (Status s = light(p, *node); !s) return s;
    } else if (type == "Skeleton") {
      if (Status s = skeleton(p, *node); !s) return s;
    } else if (is_one_of(type, {"Cube", "Sphere", "Cylinder", "Cone", "Capsule", "Plane", "BasisCurves", "NurbsCurves",
                                "HermiteCurves", "Points", "NurbsPatch", "TetMesh", "PointInstancer", "Volume"})) {
      if (visible) warn_once(type, type + " prims are not drawn (only Mesh is), first: " + p.path);
      continue;
    }
    if (Status s = traverse(p, *node, depth + 1, visible); !s) return s;
  }
  return {};
}

Status Converter::camera(const Prim& p, int node) {
  CameraDef def;
  def.name = p.name;
  def.path = p.path;
  def.orthographic = token(p, "projection").value_or("perspective") == "orthographic";
  const double focal = number(p, "focalLength").value_or(50.0);
  const double aperture = number(p, "verticalAperture").value_or(15.2908);
  const auto clipping = numbers_or(p, "clippingRange", 2, {1.0, 1000000.0});
  if (!(focal > 0.0) || !(aperture > 0.0) || clipping.size() != 2 || !(clipping[0] > 0.0) || !(clipping[1] > clipping[0]))
    return Error::input(where(p), "camera " + p.path + " has a non-positive focalLength or verticalAperture, or a "
                                  "clippingRange that is not 0 < near < far");
  def.focal_length = static_cast<float>(focal);
  def.vertical_aperture = static_cast<float>(aperture);
  def.yfov = static_cast<float>(2.0 * std::atan(0.5 * aperture / focal));
  if (!(def.yfov >= kMinCameraYfov) || !std::isfinite(clipping[1]) || !(float(clipping[0]) > 0.0f))
    return Error::input(where(p), "camera " + p.path + " has a field of view under 1e-4 radians (verticalAperture / "
                                  "focalLength too small) or a clippingRange that is not finite");
  def.znear = static_cast<float>(clipping[0]);
  def.zfar = static_cast<float>(clipping[1]);
  auto f = sampler(p, "focalLength", 1, Interpolation::Linear);
  if (!f) return f.error();
  auto a = sampler(p, "verticalAperture", 1, Interpolation::Linear);
  if (!a) return a.error();
  auto r = sampler(p, "clippingRange", 2, Interpolation::Linear);
  if (!r) return r.error();
  def.focal_sampler = *f;
  def.aperture_sampler = *a;
  def.clipping_sampler = *r;
  out.cameras.push_back(def);
  out.camera_instances.push_back({static_cast<int>(out.cameras.size()) - 1, node});
  return {};
}

// UsdLux to the KHR_lights_punctual units of LightState (docs/usd.md): intensity * 2^exposure is the
// radiance L of the light's surface; a distant light gives L lux; a sphere light L * pi r^2 candela (its
// projected area), a rect / disk light L * area candela on its axis as a 90-degree spot; `normalize` makes
// the emission independent of the size (L is then the candela / lux value). A dome light adds L * color as
// ambient radiance.
Status Converter::light(const Prim& p, int node) {
  auto input = [&](const char* name, double fallback) {
    if (auto v = number(p, std::string("inputs:") + name)) return *v;
    return number(p, name).value_or(fallback);
  };
  const double radiance = input("intensity", 1.0) * std::exp2(input("exposure", 0.0));
  const std::vector<double>* color = numbers(p, "inputs:color", 3);
  if (!color) color = numbers(p, "color", 3);
  const glm::vec3 rgb = color ? glm::vec3(float((*color)[0]), float((*color)[1]), float((*color)[2])) : glm::vec3(1.0f);
  const bool normalize = input("normalize", 0.0) != 0.0;
  const std::string& type = p.type_name;
  constexpr double kPi = 3.14159265358979323846;
  LightDef def;
  def.node = node;
  def.light.color = rgb;
  if (type == "DomeLight") {
    out.ambient += rgb * float(radiance);
    if (value(p, "inputs:texture:file") || value(p, "texture:file"))
      warn_once("dome", where(p) + ": the DomeLight's texture is not used (a uniform ambient of its intensity and colour)");
    return {};
  }
  if (type == "DistantLight") {
    def.light.type = LightState::Type::Directional;
    def.light.intensity = float(radiance);
  } else if (type == "SphereLight" || type == "CylinderLight") {
    const double r = input("radius", 0.5);
    const double area = type == "SphereLight" ? kPi * r * r : 2.0 * r * input("length", 1.0);
    def.light.type = LightState::Type::Point;
    def.light.intensity = float(normalize ? radiance : radiance * area);
  } else if (type == "RectLight" || type == "DiskLight") {
    const double r = input("radius", 0.5);
    const double area = type == "RectLight" ? input("width", 1.0) * input("height", 1.0) : kPi * r * r;
    def.light.type = LightState::Type::Spot;
    def.light.intensity = float(normalize ? radiance : radiance * area);
    def.light.inner_cone = 0.0f;
    def.light.outer_cone = float(kPi / 2.0);
  } else {
    warn_once(type, type + " prims are not replayed (distant, sphere, cylinder, rect, disk and dome lights are): " + p.path);
    return {};
  }
  if (auto angle = number(p, "inputs:shaping:cone:angle"); angle && *angle < 90.0 && def.light.type != LightState::Type::Directional) {
    // UsdLuxShapingAPI: a cone of half-angle `angle` degrees whose edge softens over `softness`.
    def.light.type = LightState::Type::Spot;
    def.light.outer_cone = float(*angle * kPi / 180.0);
    def.light.inner_cone = def.light.outer_cone * float(1.0 - std::clamp(number(p, "inputs:shaping:cone:softness").value_or(0.0), 0.0, 1.0));
  }
  out.lights.push_back(def);
  return {};
}

Status Converter::finish_time() {
  out.clip_duration = 0.0;
  if (!sampled) return {};
  const double end = stage.root_layer().has("endTimeCode") ? stage.end_time_code() : last_tc;
  // The timeline holds its last frame for one frame: startTimeCode .. endTimeCode at framesPerSecond.
  const double d = (end - start_tc + tcps / stage.frames_per_second()) / tcps;
  out.clip_duration = d > 0.0 && std::isfinite(d) ? d : 0.0;
  return {};
}

}  // namespace usd_detail

Status read_usd(const std::string& path, const SceneLoadOptions& options, SceneDescription& out) {
  if (!options.clip.empty() && options.clip != "all") {
    return Error{ErrorKind::Usage, path, "USD scenes have a single timeline, no named clips: omit --clip (or give 'all')"};
  }
  auto stage = usd::Stage::open(path);
  if (!stage) return stage.error();
  out.file = path;
  out.format = "USD";
  out.warnings = (*stage)->warnings();
  out.inputs.push_back(path);
  for (const std::string& layer : (*stage)->layer_paths())
    if (layer != path) out.inputs.push_back(layer);
  usd_detail::Converter cv(**stage, out);
  cv.start_tc = (*stage)->start_time_code();
  cv.tcps = (*stage)->time_codes_per_second();
  int root = -1;
  const std::string up = (*stage)->up_axis();
  if (up == "Z") {
    // The scene's world is Y up (docs/conventions.md): a Z-up stage turns -90 degrees about X.
    root = cv.add_node("upAxis Z to Y", -1);
    out.nodes[std::size_t(root)].rotation = glm::angleAxis(-1.5707963267948966f, glm::vec3(1.0f, 0.0f, 0.0f));
  } else if (up != "Y") {
    cv.warn("upAxis '" + up + "' is neither Y nor Z: taken as Y");
  }
  if (Status s = cv.traverse((*stage)->root(), root, 0, true); !s) return s;
  for (auto& job : cv.meshes)
    if (Status s = cv.material_slots(job); !s) return s;
  if (Status s = cv.create_materials(); !s) return s;
  for (const auto& job : cv.meshes)
    if (Status s = cv.mesh(job); !s) return s;
  if (out.draws.empty()) {
    return Error::input(path, "the stage has no mesh to draw (only Mesh prims that are defined, active, visible and of "
                              "purpose default or render are drawn)");
  }
  return cv.finish_time();
}

}  // namespace temporal::scene_detail
