#include "scene_gpu.h"

#include <glm/gtc/type_ptr.hpp>
#include <glm/matrix.hpp>

#include <algorithm>
#include <limits>

namespace temporal::render_detail {

SceneGpu::SceneGpu(const GlFunctions& gl, const SceneGeometry& scene, bool mipmaps)
    : gl_(gl), scene_(scene), mipmaps_(mipmaps) {}

SceneGpu::~SceneGpu() {
  for (auto& p : primitives_) {
    gl_.DeleteVertexArrays(1, &p.vao);
    GLuint b[] = {p.position, p.normal, p.uv, p.index};
    gl_.DeleteBuffers(4, b);
  }
  for (auto& d : deformed_) {
    if (!d.vao) continue;
    gl_.DeleteVertexArrays(1, &d.vao);
    GLuint b[] = {d.position, d.normal, d.prev_position};
    gl_.DeleteBuffers(3, b);
  }
  if (!textures_.empty()) gl_.DeleteTextures(GLsizei(textures_.size()), textures_.data());
}

void SceneGpu::setup_vao(GLuint vao, const PrimitiveBuffers& p, GLuint position, GLuint normal,
                         GLuint prev) const {
  gl_.BindVertexArray(vao);
  auto attrib = [&](GLuint location, GLuint buffer, GLint size) {
    gl_.BindBuffer(GL_ARRAY_BUFFER, buffer);
    gl_.EnableVertexAttribArray(location);
    gl_.VertexAttribPointer(location, size, GL_FLOAT, GL_FALSE, 0, nullptr);
  };
  attrib(0, position, 3);
  attrib(1, normal, 3);
  if (p.uv) {
    attrib(2, p.uv, 2);
  } else {
    gl_.DisableVertexAttribArray(2);
    gl_.VertexAttrib2f(2, 0.0f, 0.0f);
  }
  attrib(3, prev, 3);
  gl_.BindBuffer(GL_ELEMENT_ARRAY_BUFFER, p.index);
  gl_.BindVertexArray(0);
}

Status SceneGpu::upload() {
  const auto& prims = *scene_.primitives;
  primitives_.resize(prims.size());
  for (std::size_t i = 0; i < prims.size(); ++i) {
    const ScenePrimitive& src = prims[i];
    PrimitiveBuffers& p = primitives_[i];
    if (src.normals.size() != src.positions.size() ||
        (!src.texcoords.empty() && src.texcoords.size() != src.positions.size()))
      return Error::internal("primitive " + std::to_string(i) + " has attribute arrays of different lengths");
    for (std::uint32_t idx : src.indices)
      if (idx >= src.positions.size())
        return Error::internal("primitive " + std::to_string(i) + " has an index out of range");
    auto make = [&](GLenum target, const void* data, std::size_t bytes) {
      GLuint b = 0;
      gl_.GenBuffers(1, &b);
      gl_.BindBuffer(target, b);
      gl_.BufferData(target, GLsizeiptr(bytes), data, GL_STATIC_DRAW);
      return b;
    };
    p.position = make(GL_ARRAY_BUFFER, src.positions.data(), src.positions.size() * sizeof(glm::vec3));
    p.normal = make(GL_ARRAY_BUFFER, src.normals.data(), src.normals.size() * sizeof(glm::vec3));
    if (!src.texcoords.empty())
      p.uv = make(GL_ARRAY_BUFFER, src.texcoords.data(), src.texcoords.size() * sizeof(glm::vec2));
    p.index = make(GL_ELEMENT_ARRAY_BUFFER, src.indices.data(), src.indices.size() * sizeof(std::uint32_t));
    p.count = GLsizei(src.indices.size());
    gl_.GenVertexArrays(1, &p.vao);
    // Rigid draws read the rest positions twice: as this frame's and the previous frame's vertex, each
    // transformed by its own model matrix.
    setup_vao(p.vao, p, p.position, p.normal, p.position);
    p.local_min = glm::vec3(std::numeric_limits<float>::max());
    p.local_max = glm::vec3(-std::numeric_limits<float>::max());
    for (const auto& v : src.positions) {
      p.local_min = glm::min(p.local_min, v);
      p.local_max = glm::max(p.local_max, v);
    }
  }

  const auto& texs = *scene_.textures;
  textures_.assign(texs.size(), 0);
  if (!texs.empty()) gl_.GenTextures(GLsizei(texs.size()), textures_.data());
  for (std::size_t i = 0; i < texs.size(); ++i) {
    const SceneTexture& t = texs[i];
    if (t.width <= 0 || t.height <= 0 || t.rgba8.size() != std::size_t(t.width) * std::size_t(t.height) * 4)
      return Error::internal("texture " + std::to_string(i) + " has an inconsistent size");
    int levels = 1;
    if (mipmaps_)
      for (int s = std::max(t.width, t.height); s > 1; s /= 2) ++levels;
    gl_.BindTexture(GL_TEXTURE_2D, textures_[i]);
    // Rows are uploaded top row first: GL texture row 0 is then at t = 0, which is glTF's v = 0 (top).
    gl_.TexStorage2D(GL_TEXTURE_2D, levels, t.srgb ? GL_SRGB8_ALPHA8 : GL_RGBA8, t.width, t.height);
    gl_.PixelStorei(GL_UNPACK_ALIGNMENT, 1);
    gl_.TexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, t.width, t.height, GL_RGBA, GL_UNSIGNED_BYTE, t.rgba8.data());
    if (mipmaps_) gl_.GenerateMipmap(GL_TEXTURE_2D);
    auto wrap = [](bool repeat, bool mirror) {
      return mirror ? GL_MIRRORED_REPEAT : repeat ? GL_REPEAT : GL_CLAMP_TO_EDGE;
    };
    gl_.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, wrap(t.repeat_s, t.mirror_s));
    gl_.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, wrap(t.repeat_t, t.mirror_t));
    gl_.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, t.nearest ? GL_NEAREST : GL_LINEAR);
    gl_.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, mipmaps_ ? GL_LINEAR_MIPMAP_LINEAR : GL_LINEAR);
  }
  return check_gl(gl_, "scene upload");
}

Status SceneGpu::prepare(const FrameState& current, const FrameState* previous) {
  const auto& prims = *scene_.primitives;
  draws_.clear();
  draws_.reserve(current.instances.size());
  if (deformed_.size() < current.instances.size()) deformed_.resize(current.instances.size());
  frame_min_ = glm::vec3(std::numeric_limits<float>::max());
  frame_max_ = glm::vec3(-std::numeric_limits<float>::max());

  for (std::size_t i = 0; i < current.instances.size(); ++i) {
    const PrimitiveInstance& cur = current.instances[i];
    if (cur.primitive < 0 || std::size_t(cur.primitive) >= prims.size())
      return Error::internal("instance " + std::to_string(i) + " names primitive " +
                             std::to_string(cur.primitive) + " that does not exist");
    const ScenePrimitive& sp = prims[std::size_t(cur.primitive)];
    const PrimitiveBuffers& pb = primitives_[std::size_t(cur.primitive)];
    // The same instance one frame earlier: paired by index (scene.h guarantees a stable order).
    const PrimitiveInstance* prev = nullptr;
    if (previous && i < previous->instances.size() && previous->instances[i].primitive == cur.primitive)
      prev = &previous->instances[i];

    DrawItem item;
    item.index_count = pb.count;
    item.material = cur.primitive >= 0 ? sp.material : -1;
    item.id = cur.id;
    const bool deformed = cur.deformed || (prev && prev->deformed);
    if (!deformed) {
      item.vao = pb.vao;
      item.model = cur.model;
      item.prev_model = prev ? prev->model : cur.model;
      item.normal_matrix = glm::transpose(glm::inverse(glm::mat3(cur.model)));
      item.clockwise = glm::determinant(glm::mat3(cur.model)) < 0.0f;
      for (int c = 0; c < 8; ++c) {
        const glm::vec3 corner((c & 1) ? pb.local_max.x : pb.local_min.x, (c & 2) ? pb.local_max.y : pb.local_min.y,
                               (c & 4) ? pb.local_max.z : pb.local_min.z);
        const glm::vec3 w = glm::vec3(cur.model * glm::vec4(corner, 1.0f));
        frame_min_ = glm::min(frame_min_, w);
        frame_max_ = glm::max(frame_max_, w);
      }
    } else {
      // World-space vertices of both frames; a rigid side of the pair is expanded with its model matrix.
      const std::size_t n = sp.positions.size();
      auto world_of = [&](const PrimitiveInstance& inst, std::vector<glm::vec3>& out, bool normals) {
        const auto& src = normals ? inst.world_normals : inst.world_positions;
        if (inst.deformed && src.size() == n) return &src;
        out.resize(n);
        const glm::mat3 nm = glm::transpose(glm::inverse(glm::mat3(inst.model)));
        for (std::size_t v = 0; v < n; ++v)
          out[v] = normals ? glm::normalize(nm * sp.normals[v]) : glm::vec3(inst.model * glm::vec4(sp.positions[v], 1.0f));
        return static_cast<const std::vector<glm::vec3>*>(&out);
      };
      std::vector<glm::vec3> tmp_pos, tmp_nrm, tmp_prev;
      const auto* pos = world_of(cur, tmp_pos, false);
      const auto* nrm = world_of(cur, tmp_nrm, true);
      const auto* ppos = prev ? world_of(*prev, tmp_prev, false) : pos;
      DeformedBuffers& db = deformed_[i];
      if (!db.vao || db.primitive != cur.primitive) {
        if (db.vao) {
          gl_.DeleteVertexArrays(1, &db.vao);
          GLuint b[] = {db.position, db.normal, db.prev_position};
          gl_.DeleteBuffers(3, b);
        }
        gl_.GenVertexArrays(1, &db.vao);
        GLuint b[3];
        gl_.GenBuffers(3, b);
        db.position = b[0];
        db.normal = b[1];
        db.prev_position = b[2];
        db.primitive = cur.primitive;
        setup_vao(db.vao, pb, db.position, db.normal, db.prev_position);
      }
      auto stream = [&](GLuint buffer, const std::vector<glm::vec3>& data) {
        gl_.BindBuffer(GL_ARRAY_BUFFER, buffer);
        gl_.BufferData(GL_ARRAY_BUFFER, GLsizeiptr(data.size() * sizeof(glm::vec3)), data.data(), GL_STREAM_DRAW);
      };
      stream(db.position, *pos);
      stream(db.normal, *nrm);
      stream(db.prev_position, *ppos);
      item.vao = db.vao;
      for (const auto& w : *pos) {
        frame_min_ = glm::min(frame_min_, w);
        frame_max_ = glm::max(frame_max_, w);
      }
    }
    draws_.push_back(item);
  }
  if (draws_.empty()) {
    frame_min_ = scene_.bounds_min;
    frame_max_ = scene_.bounds_max;
  }
  return check_gl(gl_, "vertex upload");
}

void SceneGpu::bind_material(GLuint program, int material) const {
  static const SceneMaterial kDefault{};
  const SceneMaterial& m =
      (material >= 0 && std::size_t(material) < scene_.materials->size()) ? (*scene_.materials)[std::size_t(material)]
                                                                           : kDefault;
  const bool textured = m.base_color_texture >= 0 && std::size_t(m.base_color_texture) < textures_.size();
  gl_.Uniform4f(gl_.GetUniformLocation(program, "u_base_color"), m.base_color_factor.r, m.base_color_factor.g,
                m.base_color_factor.b, m.base_color_factor.a);
  gl_.Uniform1i(gl_.GetUniformLocation(program, "u_has_texture"), textured ? 1 : 0);
  gl_.Uniform1i(gl_.GetUniformLocation(program, "u_mask"), m.alpha_mode == SceneMaterial::AlphaMode::Mask ? 1 : 0);
  gl_.Uniform1f(gl_.GetUniformLocation(program, "u_cutoff"), m.alpha_cutoff);
  gl_.Uniform1f(gl_.GetUniformLocation(program, "u_metallic"), m.metallic);
  gl_.Uniform1f(gl_.GetUniformLocation(program, "u_roughness"), m.roughness);
  gl_.ActiveTexture(GL_TEXTURE0);
  gl_.BindTexture(GL_TEXTURE_2D, textured ? textures_[std::size_t(m.base_color_texture)] : 0);
}

void SceneGpu::draw_all(GLuint program, bool cull) const {
  const GLint l_model = gl_.GetUniformLocation(program, "u_model");
  const GLint l_prev = gl_.GetUniformLocation(program, "u_prev_model");
  const GLint l_nm = gl_.GetUniformLocation(program, "u_normal_matrix");
  const GLint l_id = gl_.GetUniformLocation(program, "u_id");
  gl_.Uniform1i(gl_.GetUniformLocation(program, "u_texture"), 0);
  int bound_material = -2;
  for (const DrawItem& d : draws_) {
    if (d.material != bound_material) {
      bind_material(program, d.material);
      bound_material = d.material;
    }
    static const SceneMaterial kDefault{};
    const SceneMaterial& m = (d.material >= 0 && std::size_t(d.material) < scene_.materials->size())
                                 ? (*scene_.materials)[std::size_t(d.material)]
                                 : kDefault;
    // glTF: single-sided materials cull back faces; double-sided ones are lit from the side seen.
    if (cull && !m.double_sided) {
      gl_.Enable(GL_CULL_FACE);
      gl_.CullFace(GL_BACK);
      gl_.FrontFace(d.clockwise ? GL_CW : GL_CCW);
    } else {
      gl_.Disable(GL_CULL_FACE);
      gl_.FrontFace(d.clockwise ? GL_CW : GL_CCW);
    }
    gl_.UniformMatrix4fv(l_model, 1, GL_FALSE, glm::value_ptr(d.model));
    gl_.UniformMatrix4fv(l_prev, 1, GL_FALSE, glm::value_ptr(d.prev_model));
    gl_.UniformMatrix3fv(l_nm, 1, GL_FALSE, glm::value_ptr(d.normal_matrix));
    if (l_id >= 0) gl_.Uniform1ui(l_id, d.id);
    gl_.BindVertexArray(d.vao);
    gl_.DrawElements(GL_TRIANGLES, d.index_count, GL_UNSIGNED_INT, nullptr);
  }
  gl_.BindVertexArray(0);
  gl_.Disable(GL_CULL_FACE);
}

}  // namespace temporal::render_detail
