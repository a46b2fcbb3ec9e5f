// UsdGeomMesh to triangles: polygons fan-triangulated (leftHanded orientation flips the winding, holeIndices
// are skipped), primvars read with their interpolation (constant, uniform, vertex, varying, faceVarying) and
// indices, st flipped to the glTF convention (v = 1 - t), smooth normals where the mesh has none, GeomSubsets
// with their own material binding split into primitives, time-sampled points replayed as a point cache.
// Subdivision surfaces are drawn as their control cage.
#include "scene_mesh.h"
#include "usd_convert.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace temporal::scene_detail::usd_detail {
namespace {

enum class Interp { Constant, Uniform, Vertex, FaceVarying };

// A primvar resolved for lookup by face, point and face-vertex.
struct Primvar {
  const std::vector<double>* values = nullptr;
  std::vector<double> indices;  // empty: not indexed
  int tuple = 1;
  Interp interp = Interp::Vertex;
  explicit operator bool() const { return values != nullptr; }
  // Element for face f, point p, face-vertex fv.
  const double* at(std::size_t f, std::size_t p, std::size_t fv) const {
    std::size_t e = interp == Interp::Constant ? 0 : interp == Interp::Uniform ? f : interp == Interp::Vertex ? p : fv;
    if (!indices.empty()) e = static_cast<std::size_t>(indices[e]);
    return values->data() + e * std::size_t(tuple);
  }
};

// The arrays live in the stage's layers (no copies).
struct Topology {
  const std::vector<double>* points = nullptr;
  const std::vector<double>* counts = nullptr;
  const std::vector<double>* indices = nullptr;
  std::vector<std::size_t> face_start;  // first face-vertex of each face
  std::size_t faces = 0, point_count = 0;
};

}  // namespace

namespace {

// Reads primvar `name` (with `name:indices`) and checks its element count against its interpolation.
Primvar read_primvar(const Converter& cv, const Prim& p, const std::string& name, int tuple, Interp fallback,
                     const Topology& topo, std::vector<std::string>& problems) {
  Primvar pv;
  const Value* v = cv.value(p, name);
  if (!v) return pv;
  if (v->kind != Value::Kind::Number || v->tuple != tuple) {
    problems.push_back(name + " does not hold " + std::to_string(tuple) + "-component values");
    return pv;
  }
  pv.values = &v->numbers;
  pv.tuple = tuple;
  pv.interp = fallback;
  if (const Value* interp = p.property_meta(name, "interpolation"); interp && interp->text.size() == 1) {
    const std::string& t = interp->text[0];
    pv.interp = t == "constant" ? Interp::Constant : t == "uniform" ? Interp::Uniform
                : t == "faceVarying" ? Interp::FaceVarying : Interp::Vertex;  // vertex, varying
  }
  if (const Value* idx = cv.value(p, name + ":indices"); idx && idx->kind == Value::Kind::Number) pv.indices = idx->numbers;
  const std::size_t elements = pv.values->size() / std::size_t(tuple);
  const std::size_t needed = pv.interp == Interp::Constant ? 1
                             : pv.interp == Interp::Uniform ? topo.faces
                             : pv.interp == Interp::Vertex ? topo.point_count
                                                           : topo.indices->size();
  const std::size_t have = pv.indices.empty() ? elements : pv.indices.size();
  bool ok = pv.interp == Interp::Constant ? have >= 1 : have == needed;
  for (double i : pv.indices) ok = ok && i >= 0.0 && i < double(elements) && i == std::floor(i);
  if (!ok) {
    problems.push_back(name + " has " + std::to_string(have) + " elements for its interpolation (" + std::to_string(needed) +
                       " needed) or an index out of range");
    return Primvar{};
  }
  return pv;
}

Status read_topology(const Converter& cv, const Prim& p, Topology& t) {
  t.points = cv.numbers(p, "points", 3);
  t.counts = cv.numbers(p, "faceVertexCounts", 1);
  t.indices = cv.numbers(p, "faceVertexIndices", 1);
  if (!t.points || !t.counts || !t.indices)
    return Error::input(where(p), "mesh " + p.path + " lacks points, faceVertexCounts or faceVertexIndices");
  t.point_count = t.points->size() / 3;
  t.faces = t.counts->size();
  if (!std::all_of(t.points->begin(), t.points->end(), [](double x) { return std::isfinite(x); }))
    return Error::input(where(p), "the points of mesh " + p.path + " hold NaN or infinite values");
  std::size_t sum = 0;
  t.face_start.resize(t.faces);
  for (std::size_t f = 0; f < t.faces; ++f) {
    const double c = (*t.counts)[f];
    if (!(c >= 0.0) || c != std::floor(c) || c > double(t.indices->size()))
      return Error::input(where(p), "faceVertexCounts[" + std::to_string(f) + "] of mesh " + p.path + " is not a valid count");
    t.face_start[f] = sum;
    sum += static_cast<std::size_t>(c);
  }
  if (sum != t.indices->size())
    return Error::input(where(p), "mesh " + p.path + ": faceVertexCounts add up to " + std::to_string(sum) +
                                      " but faceVertexIndices has " + std::to_string(t.indices->size()) + " entries");
  for (std::size_t i = 0; i < t.indices->size(); ++i) {
    const double x = (*t.indices)[i];
    if (!(x >= 0.0) || x >= double(t.point_count) || x != std::floor(x))
      return Error::input(where(p), "faceVertexIndices[" + std::to_string(i) + "] = " + std::to_string(x) + " of mesh " + p.path +
                                        " is out of range (the mesh has " + std::to_string(t.point_count) + " points)");
  }
  return {};
}

// Area-weighted smooth normals per point, then per vertex.
std::vector<glm::vec3> smooth_normals(const std::vector<glm::vec3>& positions, const std::vector<std::uint32_t>& tris,
                                      const std::vector<std::uint32_t>& vertex_point, std::size_t point_count) {
  std::vector<glm::vec3> per_point(point_count, glm::vec3(0.0f));
  auto point = [&](std::uint32_t v) { return vertex_point.empty() ? v : vertex_point[v]; };
  for (std::size_t t = 0; t + 2 < tris.size(); t += 3) {
    const glm::vec3 n = glm::cross(positions[tris[t + 1]] - positions[tris[t]], positions[tris[t + 2]] - positions[tris[t]]);
    for (int k = 0; k < 3; ++k) per_point[point(tris[t + std::size_t(k)])] += n;
  }
  std::vector<glm::vec3> out(positions.size());
  for (std::size_t v = 0; v < out.size(); ++v) out[v] = per_point[point(std::uint32_t(v))];
  return out;
}

// Renumbers `indices` to the vertices they use, in order of first use; returns the old index of each
// new vertex (a GeomSubset's primitive keeps only its own vertices).
std::vector<std::uint32_t> remap_used(std::vector<std::uint32_t>& indices, std::size_t vertex_count) {
  std::vector<std::uint32_t> used(vertex_count, ~0u), keep;
  for (auto& i : indices) {
    if (used[i] == ~0u) {
      used[i] = static_cast<std::uint32_t>(keep.size());
      keep.push_back(i);
    }
    i = used[i];
  }
  return keep;
}

// Vertices and per-slot triangles of a mesh.
struct MeshBuild {
  ScenePrimitive full;  // every vertex
  PrimitiveData data;
  std::vector<std::vector<std::uint32_t>> slot_tris;
  std::vector<std::uint32_t> corner_of;  // vertex -> face-vertex (when one vertex per face-vertex)
  std::size_t skipped = 0;               // faces of fewer than 3 vertices
};

struct Faces {
  const std::vector<char>& hole;
  const std::vector<int>& slot;
  bool left_handed = false;
  bool corners = false;  // one vertex per face-vertex (a primitive varies per face or face-vertex)
};

// Fans every face from its first vertex (the other way round for leftHanded meshes) into its slot's triangles.
void triangulate(const Topology& topo, const Primvar& normals, const Primvar& st, const Faces& faces, MeshBuild& b) {
  std::vector<std::uint32_t> face;
  for (std::size_t f = 0; f < topo.faces; ++f) {
    const std::size_t n = std::size_t((*topo.counts)[f]), s0 = topo.face_start[f];
    if (faces.hole[f] || n < 3) {
      b.skipped += n < 3 && !faces.hole[f];
      continue;
    }
    face.resize(n);
    for (std::size_t k = 0; k < n; ++k) {
      const std::size_t fv = s0 + k, pt = std::size_t((*topo.indices)[fv]);
      if (!faces.corners) {
        face[k] = std::uint32_t(pt);
        continue;
      }
      face[k] = std::uint32_t(b.full.positions.size());
      b.full.positions.emplace_back((*topo.points)[3 * pt], (*topo.points)[3 * pt + 1], (*topo.points)[3 * pt + 2]);
      if (normals) {
        const double* nv = normals.at(f, pt, fv);
        b.full.normals.emplace_back(nv[0], nv[1], nv[2]);
      }
      if (st) {
        const double* t = st.at(f, pt, fv);
        b.full.texcoords.emplace_back(float(t[0]), float(1.0 - t[1]));
      }
      b.corner_of.push_back(std::uint32_t(fv));
      b.data.vertex_point.push_back(std::uint32_t(pt));
    }
    auto& tris = b.slot_tris[std::size_t(faces.slot[f])];
    for (std::size_t k = 1; k + 1 < n; ++k) {
      if (faces.left_handed) tris.insert(tris.end(), {face[0], face[k + 1], face[k]});
      else tris.insert(tris.end(), {face[0], face[k], face[k + 1]});
    }
  }
  if (faces.corners) return;
  b.full.positions.resize(topo.point_count);
  for (std::size_t i = 0; i < topo.point_count; ++i)
    b.full.positions[i] = glm::vec3(float((*topo.points)[3 * i]), float((*topo.points)[3 * i + 1]), float((*topo.points)[3 * i + 2]));
  if (normals) {
    b.full.normals.resize(topo.point_count);
    for (std::size_t i = 0; i < topo.point_count; ++i) {
      const double* nv = normals.at(0, i, 0);
      b.full.normals[i] = glm::vec3(float(nv[0]), float(nv[1]), float(nv[2]));
    }
  }
  if (st) {
    b.full.texcoords.resize(topo.point_count);
    for (std::size_t i = 0; i < topo.point_count; ++i) {
      const double* t = st.at(0, i, 0);
      b.full.texcoords[i] = glm::vec2(float(t[0]), float(1.0 - t[1]));
    }
  }
}

}  // namespace

Status Converter::mesh(const MeshJob& job) {
  const Prim& p = *job.prim;
  Topology topo;
  if (Status s = read_topology(*this, p, topo); !s) return s;
  const std::string scheme = token(p, "subdivisionScheme").value_or("catmullClark");
  if (scheme != "none") {
    warn_once("subdiv:" + scheme, "meshes with subdivisionScheme '" + scheme + "' (first: " + p.path +
                                      ") are drawn as their control cage: subdivision is not evaluated");
  }
  std::vector<char> hole(topo.faces, 0);
  if (const auto* holes = numbers(p, "holeIndices", 1))
    for (double h : *holes)
      if (h >= 0.0 && h < double(topo.faces)) hole[std::size_t(h)] = 1;
  const int first_material = material_index.at(job.material_keys[0]);
  const std::string uv_name = "primvars:" + uv_primvar[std::size_t(first_material)];
  std::vector<std::string> problems;
  Primvar normals = read_primvar(*this, p, "primvars:normals", 3, Interp::Vertex, topo, problems);
  if (!normals) normals = read_primvar(*this, p, "normals", 3, Interp::Vertex, topo, problems);
  const Primvar st = read_primvar(*this, p, uv_name, 2, Interp::Vertex, topo, problems);
  for (const auto& pr : problems) warn(where(p) + ": " + pr + ": ignored");

  std::vector<int> slot(topo.faces, 0);
  for (std::size_t k = 0; k < job.slot_faces.size(); ++k)
    for (int f : job.slot_faces[k])
      if (f >= 0 && std::size_t(f) < topo.faces) slot[std::size_t(f)] = int(k) + 1;
  Faces faces{hole, slot};
  faces.left_handed = token(p, "orientation").value_or("rightHanded") == "leftHanded";
  faces.corners = (normals && (normals.interp == Interp::Uniform || normals.interp == Interp::FaceVarying)) ||
                  (st && (st.interp == Interp::Uniform || st.interp == Interp::FaceVarying));
  MeshBuild b;
  b.slot_tris.resize(job.material_keys.size());
  triangulate(topo, normals, st, faces, b);
  if (b.skipped) warn(where(p) + ": " + std::to_string(b.skipped) + " faces of mesh " + p.path + " have fewer than 3 vertices: skipped");
  std::vector<std::uint32_t> all_tris;
  for (const auto& t : b.slot_tris) all_tris.insert(all_tris.end(), t.begin(), t.end());
  if (all_tris.empty()) {
    warn(where(p) + ": mesh " + p.path + " has no triangles: skipped");
    return {};
  }
  if (!normals) {
    b.full.normals = smooth_normals(b.full.positions, all_tris, b.data.vertex_point, topo.point_count);
    b.data.smooth_normals = true;
  } else if (!std::all_of(b.full.normals.begin(), b.full.normals.end(), [](const glm::vec3& n) {
               return std::isfinite(n.x) && std::isfinite(n.y) && std::isfinite(n.z);
             })) {
    // Checked before normalising, which would quietly replace them (docs/render-gbuffer.md: exit 2).
    return Error::input(where(p), "the normals of mesh " + p.path + " hold NaN or infinite values");
  }
  normalise_normals(b.full.normals);

  // Point cache: time-sampled points (and normals) replace the rest values every evaluation.
  auto points_sampler = sampler(p, "points", int(3 * topo.point_count), Interpolation::Linear);
  if (!points_sampler) return points_sampler.error();
  b.data.point_sampler = *points_sampler;
  if (b.data.point_sampler >= 0 && normals && normals.indices.empty() &&
      (normals.interp == Interp::Vertex || normals.interp == Interp::FaceVarying)) {
    const bool fv = normals.interp == Interp::FaceVarying;
    auto ns = sampler(p, p.attribute("primvars:normals") ? "primvars:normals" : "normals",
                      int(3 * (fv ? topo.indices->size() : topo.point_count)), Interpolation::Linear);
    if (!ns) return ns.error();
    b.data.normal_sampler = *ns;
    if (fv) b.data.vertex_normal = b.corner_of;
  }
  if (Status s = bind_skin(p, job.node, topo.point_count, b.full, b.data); !s) return s;
  emit_primitives(job, b.full, b.data, b.slot_tris);
  return {};
}

// One primitive and draw per non-empty slot. Meshes without GeomSubset materials have one slot and keep every
// vertex; each subset's primitive keeps only its own vertices, with their skin and morph data.
void Converter::emit_primitives(const MeshJob& job, ScenePrimitive& full, PrimitiveData& data,
                                std::vector<std::vector<std::uint32_t>>& slot_tris) {
  const std::size_t used_slots = std::size_t(std::count_if(slot_tris.begin(), slot_tris.end(), [](const auto& t) { return !t.empty(); }));
  for (std::size_t k = 0; k < slot_tris.size(); ++k) {
    if (slot_tris[k].empty()) continue;
    ScenePrimitive prim = used_slots == 1 ? std::move(full) : full;
    PrimitiveData pd = used_slots == 1 ? std::move(data) : data;
    prim.indices = std::move(slot_tris[k]);
    if (used_slots > 1) {
      const std::vector<std::uint32_t> keep = remap_used(prim.indices, prim.positions.size());
      prim.positions = expand(prim.positions, keep, 1);
      prim.normals = expand(prim.normals, keep, 1);
      if (!prim.texcoords.empty()) prim.texcoords = expand(prim.texcoords, keep, 1);
      if (pd.influences > 0) {
        pd.joints = expand(pd.joints, keep, std::size_t(pd.influences));
        pd.weights = expand(pd.weights, keep, std::size_t(pd.influences));
      }
      for (auto& tp : pd.target_positions) tp = expand(tp, keep, 1);
      for (auto& tn : pd.target_normals)
        if (!tn.empty()) tn = expand(tn, keep, 1);
      pd.vertex_point = pd.vertex_point.empty() ? keep : expand(pd.vertex_point, keep, 1);
      if (!pd.vertex_normal.empty()) pd.vertex_normal = expand(pd.vertex_normal, keep, 1);
    }
    prim.material = material_index.at(job.material_keys[k]);
    compute_local_bounds(prim, pd);
    out.primitives.push_back(std::move(prim));
    out.primitive_data.push_back(std::move(pd));
    out.draws.push_back({job.node, static_cast<int>(out.primitives.size()) - 1});
  }
}

}  // namespace temporal::scene_detail::usd_detail
