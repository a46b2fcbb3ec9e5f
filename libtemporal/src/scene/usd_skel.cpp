// UsdSkel to nodes, skins and morph targets: a Skeleton's joints become nodes below the Skeleton prim's node
// (their local transforms from the bound SkelAnimation's translations, rotations and scales, else the
// restTransforms); a mesh bound to it (skel:skeleton on the mesh or an ancestor) with
// primvars:skel:jointIndices / jointWeights gets a skin whose inverse bind matrices are
// inverse(bindTransforms[j]) * primvars:skel:geomBindTransform, so that the skinned point is
// sum_j w_j * world(joint j) * inverse(bind_j) * geomBind * p: UsdSkel's linear blend skinning in skeleton
// space, placed in the world by the skeleton's transform (the mesh's own transform is ignored, as UsdSkel and
// glTF both specify). skel:blendShapes become morph targets weighted by the animation's blendShapeWeights,
// applied before skinning.
#include "scene_mesh.h"
#include "usd_convert.h"

#include <glm/gtc/type_ptr.hpp>
#include <glm/gtx/matrix_decompose.hpp>

#include <algorithm>
#include <cmath>

namespace temporal::scene_detail::usd_detail {
namespace {

std::vector<std::string> tokens(const Converter& cv, const Prim& p, std::string_view name) {
  const Value* v = cv.value(p, name);
  return v && v->kind == Value::Kind::String ? v->text : std::vector<std::string>{};
}

// The first target of `rel` on `prim` or its nearest ancestor that authors it (UsdSkelBindingAPI inherits).
const Prim* inherited_target(const usd::Stage& stage, const Prim& prim, const char* rel) {
  for (const Prim* q = &prim; q && q->path != "/"; q = q->parent) {
    if (!q->property(rel)) continue;
    const auto t = q->targets(rel);
    return t.empty() ? nullptr : stage.prim_at(t.front());
  }
  return nullptr;
}

std::vector<std::string> inherited_tokens(const Converter& cv, const Prim& prim, const char* name) {
  for (const Prim* q = &prim; q && q->path != "/"; q = q->parent) {
    if (q->attribute(name)) return tokens(cv, *q, name);
  }
  return {};
}

void quats_to_xyzw(const double* in, float* out, int components) {
  for (int i = 0; i + 3 < components; i += 4) {
    out[i] = float(in[i + 1]);
    out[i + 1] = float(in[i + 2]);
    out[i + 2] = float(in[i + 3]);
    out[i + 3] = float(in[i]);
  }
}

glm::mat4 matrix_at(const std::vector<double>& m, std::size_t k) {
  float f[16];
  for (int i = 0; i < 16; ++i) f[i] = float(m[16 * k + std::size_t(i)]);
  return glm::make_mat4(f);  // USD's rows are glm's columns
}

}  // namespace

int Converter::slice(int whole, int first, int count) {
  const Sampler& w = out.samplers[std::size_t(whole)];
  Sampler s;
  s.components = count;
  s.interpolation = w.interpolation;
  s.times = w.times;
  s.values.resize(w.times.size() * std::size_t(count));
  for (std::size_t k = 0; k < w.times.size(); ++k)
    for (int c = 0; c < count; ++c)
      s.values[k * std::size_t(count) + std::size_t(c)] = w.values[k * std::size_t(w.components) + std::size_t(first + c)];
  out.samplers.push_back(std::move(s));
  return static_cast<int>(out.samplers.size()) - 1;
}

Status Converter::skeleton(const Prim& p, int node) {
  Skeleton sk;
  sk.path = p.path;
  sk.joints = tokens(*this, p, "joints");
  const std::size_t n = sk.joints.size();
  const std::vector<double>* bind = numbers(p, "bindTransforms", 16);
  const std::vector<double>* rest = numbers(p, "restTransforms", 16);
  if (n > 0 && (!bind || bind->size() != 16 * n))
    return Error::input(where(p), "skeleton " + p.path + " needs one bindTransforms matrix per joint (" + std::to_string(n) + ")");
  if (rest && rest->size() != 16 * n) rest = nullptr;
  for (std::size_t j = 0; j < n; ++j) sk.bind.push_back(matrix_at(*bind, j));

  // The bound animation (skel:animationSource on the skeleton or an ancestor) and its joint order.
  const Prim* anim = inherited_target(stage, p, "skel:animationSource");
  if (anim && anim->type_name != "SkelAnimation") anim = nullptr;
  std::vector<int> anim_of(n, -1);
  std::vector<std::string> anim_joints = anim ? tokens(*this, *anim, "joints") : std::vector<std::string>{};
  for (std::size_t a = 0; a < anim_joints.size(); ++a) {
    auto it = std::find(sk.joints.begin(), sk.joints.end(), anim_joints[a]);
    if (it != sk.joints.end()) anim_of[std::size_t(it - sk.joints.begin())] = int(a);
  }
  const int na = int(anim_joints.size());
  int samplers[3] = {-1, -1, -1};
  const std::vector<double>* constants[3] = {nullptr, nullptr, nullptr};
  const char* names[3] = {"translations", "rotations", "scales"};
  for (int c = 0; c < 3 && anim; ++c) {
    const int comps = c == 1 ? 4 : 3;
    auto s = sampler(*anim, names[c], comps * na, Interpolation::Linear, c == 1 ? quats_to_xyzw : nullptr);
    if (!s) return s.error();
    samplers[c] = *s;
    constants[c] = numbers(*anim, names[c], comps);
    if (constants[c] && constants[c]->size() != std::size_t(comps * na)) constants[c] = nullptr;
  }
  for (std::size_t j = 0; j < n; ++j) {
    const std::string& path = sk.joints[j];
    const std::size_t slash = path.rfind('/');
    int parent = node;
    if (slash != std::string::npos) {
      auto it = std::find(sk.joints.begin(), sk.joints.begin() + std::ptrdiff_t(j), path.substr(0, slash));
      if (it == sk.joints.begin() + std::ptrdiff_t(j))
        return Error::input(where(p), "joint '" + path + "' of skeleton " + p.path + " comes before its parent (or has none)");
      parent = sk.joint_nodes[std::size_t(it - sk.joints.begin())];
    }
    const int jn = add_node(slash == std::string::npos ? path : path.substr(slash + 1), parent);
    sk.joint_nodes.push_back(jn);
    Node& nd = out.nodes[std::size_t(jn)];
    // Rest: restTransforms, else the bind pose relative to the parent joint.
    glm::mat4 local = rest ? matrix_at(*rest, j)
                           : (slash == std::string::npos ? sk.bind[j] : glm::inverse(sk.bind[std::size_t(std::find(sk.joints.begin(), sk.joints.end(), path.substr(0, slash)) - sk.joints.begin())]) * sk.bind[j]);
    const int a = anim_of[j];
    if (a < 0) {
      nd.matrix = local;
      nd.use_matrix = true;
      continue;
    }
    glm::vec3 skew;
    glm::vec4 persp;
    glm::decompose(local, nd.scale, nd.rotation, nd.translation, skew, persp);
    const TargetPath paths[3] = {TargetPath::Translation, TargetPath::Rotation, TargetPath::Scale};
    for (int c = 0; c < 3; ++c) {
      const int comps = c == 1 ? 4 : 3;
      if (samplers[c] >= 0) {
        out.channels.push_back({jn, paths[c], slice(samplers[c], a * comps, comps)});
      } else if (constants[c]) {
        const double* v = constants[c]->data() + std::size_t(a * comps);
        if (c == 0) nd.translation = glm::vec3(float(v[0]), float(v[1]), float(v[2]));
        if (c == 1) nd.rotation = glm::normalize(glm::quat(float(v[0]), float(v[1]), float(v[2]), float(v[3])));
        if (c == 2) nd.scale = glm::vec3(float(v[0]), float(v[1]), float(v[2]));
      }
    }
  }
  if (anim) {
    sk.blend_shapes = tokens(*this, *anim, "blendShapes");
    const int nb = int(sk.blend_shapes.size());
    auto w = sampler(*anim, "blendShapeWeights", nb, Interpolation::Linear);
    if (!w) return w.error();
    sk.blend_weight_sampler = *w;
    if (const auto* rw = numbers(*anim, "blendShapeWeights", 1); rw && rw->size() == std::size_t(nb))
      for (double x : *rw) sk.blend_weight_rest.push_back(float(x));
  }
  skeletons[p.path] = std::move(sk);
  return {};
}

namespace {

struct Influences {
  const std::vector<double>* indices = nullptr;
  const std::vector<double>* weights = nullptr;
  int size = 1;
  bool constant = false;
};

Status read_influences(const Converter& cv, const Prim& mesh, std::size_t points, Influences& in) {
  auto idx = cv.numbers(mesh, "primvars:skel:jointIndices", 1);
  auto w = cv.numbers(mesh, "primvars:skel:jointWeights", 1);
  if (!idx || !w) return Error::input(where(mesh), "mesh " + mesh.path + " has skel:jointIndices without jointWeights (or the reverse)");
  const Value* es = mesh.property_meta("primvars:skel:jointIndices", "elementSize");
  in.size = es && es->kind == Value::Kind::Number && es->numbers.size() == 1 ? int(es->numbers[0]) : 1;
  const Value* interp = mesh.property_meta("primvars:skel:jointIndices", "interpolation");
  in.constant = interp && interp->text.size() == 1 && interp->text[0] == "constant";
  const std::size_t expect = std::size_t(std::max(in.size, 0)) * (in.constant ? 1 : points);
  if (in.size < 1 || in.size > 64 || idx->size() != expect || w->size() != expect)
    return Error::input(where(mesh), "mesh " + mesh.path + ": skel:jointIndices / jointWeights need elementSize (" +
                                         std::to_string(in.size) + ") values per " + (in.constant ? "mesh" : "point") +
                                         " (" + std::to_string(expect) + "), they hold " + std::to_string(idx->size()) + " / " +
                                         std::to_string(w->size()));
  in.indices = idx;
  in.weights = w;
  return {};
}

}  // namespace

Status Converter::bind_skin(const Prim& mesh, int node, std::size_t point_count, ScenePrimitive& prim, PrimitiveData& data) {
  const bool has_joints = mesh.attribute("primvars:skel:jointIndices") != nullptr;
  const auto shapes = tokens(*this, mesh, "skel:blendShapes");
  if (!has_joints && shapes.empty()) return {};
  // UsdSkel deforms only below a SkelRoot (a baked file keeps the skinning data under a plain Xform).
  bool under_root = false;
  for (const Prim* q = &mesh; q && !under_root; q = q->parent) under_root = q->type_name == "SkelRoot";
  if (!under_root) return {};
  const Prim* skel_prim = inherited_target(stage, mesh, "skel:skeleton");
  auto sk_it = skel_prim ? skeletons.find(skel_prim->path) : skeletons.end();
  if (sk_it == skeletons.end()) {
    warn(where(mesh) + ": mesh " + mesh.path + " has skinning data but no drawn Skeleton bound (skel:skeleton): drawn unskinned");
    return {};
  }
  const Skeleton& sk = sk_it->second;
  const std::size_t nv = prim.positions.size();
  auto point = [&](std::size_t v) { return data.vertex_point.empty() ? v : std::size_t(data.vertex_point[v]); };
  if (has_joints && !sk.joints.empty()) {
    Influences in;
    if (Status s = read_influences(*this, mesh, point_count, in); !s) return s;
    // skel:joints (on the mesh or an ancestor) reorders the skeleton's joints for this mesh's indices.
    std::vector<int> order;
    const auto mesh_joints = inherited_tokens(*this, mesh, "skel:joints");
    for (const std::string& j : mesh_joints) {
      auto it = std::find(sk.joints.begin(), sk.joints.end(), j);
      if (it == sk.joints.end()) return Error::input(where(mesh), "skel:joints of " + mesh.path + " names '" + j + "', not a joint of " + sk.path);
      order.push_back(int(it - sk.joints.begin()));
    }
    if (order.empty())
      for (std::size_t j = 0; j < sk.joints.size(); ++j) order.push_back(int(j));
    const auto geom = numbers(mesh, "primvars:skel:geomBindTransform", 16);
    const glm::mat4 geom_bind = geom ? matrix_at(*geom, 0) : glm::mat4(1.0f);
    Skin skin;
    skin.blend_normal_matrices = true;  // as OpenUSD skins normals
    for (int j : order) {
      skin.joints.push_back(sk.joint_nodes[std::size_t(j)]);
      skin.inverse_bind.push_back(geom ? glm::inverse(sk.bind[std::size_t(j)]) * geom_bind : glm::inverse(sk.bind[std::size_t(j)]));
    }
    data.influences = in.size;
    data.joints.resize(nv * std::size_t(in.size));
    data.weights.resize(nv * std::size_t(in.size));
    for (std::size_t v = 0; v < nv; ++v) {
      const std::size_t base = in.constant ? 0 : point(v) * std::size_t(in.size);
      for (int c = 0; c < in.size; ++c) {
        const double ji = (*in.indices)[base + std::size_t(c)];
        const double w = (*in.weights)[base + std::size_t(c)];
        const bool used = std::isfinite(w) && w > 0.0;
        if (used && !(ji >= 0.0 && ji < double(order.size())))
          return Error::input(where(mesh), "skel:jointIndices of " + mesh.path + " holds " + std::to_string(ji) +
                                               ", but the mesh binds " + std::to_string(order.size()) + " joints");
        data.joints[v * std::size_t(in.size) + std::size_t(c)] = used ? std::uint16_t(ji) : std::uint16_t(0);
        data.weights[v * std::size_t(in.size) + std::size_t(c)] = used ? float(w) : 0.0f;
      }
    }
    normalise_skin_weights(data, nv);
    out.skins.push_back(std::move(skin));
    out.nodes[std::size_t(node)].skin = static_cast<int>(out.skins.size()) - 1;
    prim.skinned = true;
  }
  if (!shapes.empty()) return blend_shapes(mesh, node, sk, shapes, point_count, prim, data);
  return {};
}

Status Converter::blend_shapes(const Prim& mesh, int node, const Skeleton& sk, const std::vector<std::string>& shapes,
                               std::size_t point_count, ScenePrimitive& prim, PrimitiveData& data) {
  const auto targets = mesh.targets("skel:blendShapeTargets");
  if (targets.size() != shapes.size())
    return Error::input(where(mesh), "mesh " + mesh.path + " names " + std::to_string(shapes.size()) +
                                         " skel:blendShapes but " + std::to_string(targets.size()) + " skel:blendShapeTargets");
  const std::size_t nv = prim.positions.size();
  auto point = [&](std::size_t v) { return data.vertex_point.empty() ? v : std::size_t(data.vertex_point[v]); };
  for (std::size_t k = 0; k < shapes.size(); ++k) {
    const Prim* shape = stage.prim_at(targets[k]);
    const std::vector<double>* offsets = shape ? numbers(*shape, "offsets", 3) : nullptr;
    if (!offsets) return Error::input(where(mesh), "blend shape target " + targets[k] + " of " + mesh.path + " has no offsets");
    const std::vector<double>* indices = numbers(*shape, "pointIndices", 1);
    const std::size_t count = offsets->size() / 3;
    if (indices ? indices->size() != count : count != point_count)
      return Error::input(where(*shape), "blend shape " + shape->path + ": offsets and pointIndices (or the mesh's points) differ in count");
    std::vector<glm::vec3> dense(point_count, glm::vec3(0.0f));
    for (std::size_t i = 0; i < count; ++i) {
      const double pi = indices ? (*indices)[i] : double(i);
      if (!(pi >= 0.0 && pi < double(point_count))) return Error::input(where(*shape), "pointIndices of " + shape->path + " out of range");
      dense[std::size_t(pi)] = glm::vec3(float((*offsets)[3 * i]), float((*offsets)[3 * i + 1]), float((*offsets)[3 * i + 2]));
    }
    for (const usd::Site& s : shape->sites)
      for (const auto& prop : s.spec->properties)
        if (prop.name.rfind("inbetweens:", 0) == 0) warn_once("inb", "blend shape inbetweens are not applied (first: " + shape->path + ")");
    std::vector<glm::vec3> per_vertex(nv);
    for (std::size_t v = 0; v < nv; ++v) per_vertex[v] = dense[point(v)];
    data.target_positions.push_back(std::move(per_vertex));
    data.target_normals.emplace_back();
  }
  // Weights: the animation's blendShapeWeights reordered to this mesh's skel:blendShapes.
  Node& nd = out.nodes[std::size_t(node)];
  const int n = int(shapes.size());
  nd.weight_offset = out.weight_total;
  nd.weight_count = n;
  out.weight_total += n;
  std::vector<int> from(std::size_t(n), -1);
  for (int k = 0; k < n; ++k) {
    auto it = std::find(sk.blend_shapes.begin(), sk.blend_shapes.end(), shapes[std::size_t(k)]);
    if (it != sk.blend_shapes.end()) from[std::size_t(k)] = int(it - sk.blend_shapes.begin());
  }
  nd.rest_weights.assign(std::size_t(n), 0.0f);
  for (int k = 0; k < n; ++k)
    if (from[std::size_t(k)] >= 0 && std::size_t(from[std::size_t(k)]) < sk.blend_weight_rest.size())
      nd.rest_weights[std::size_t(k)] = sk.blend_weight_rest[std::size_t(from[std::size_t(k)])];
  if (sk.blend_weight_sampler >= 0) {
    const Sampler& src = out.samplers[std::size_t(sk.blend_weight_sampler)];
    Sampler s;
    s.components = n;
    s.interpolation = src.interpolation;
    s.times = src.times;
    s.values.assign(src.times.size() * std::size_t(n), 0.0f);
    for (std::size_t t = 0; t < src.times.size(); ++t)
      for (int k = 0; k < n; ++k)
        if (from[std::size_t(k)] >= 0)
          s.values[t * std::size_t(n) + std::size_t(k)] = src.values[t * std::size_t(src.components) + std::size_t(from[std::size_t(k)])];
    out.samplers.push_back(std::move(s));
    out.channels.push_back({node, TargetPath::Weights, static_cast<int>(out.samplers.size()) - 1});
  }
  prim.morphed = true;
  return {};
}

}  // namespace temporal::scene_detail::usd_detail
