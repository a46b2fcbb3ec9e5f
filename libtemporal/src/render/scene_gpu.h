// The scene on the GPU: vertex buffers of every primitive, textures, and the per-frame draw list that
// pairs this frame's instances with the previous frame's (motion vectors). Internal to src/render.
#pragma once

#include "gl_api.h"

#include "temporal/render/render.h"

#include <glm/mat3x3.hpp>
#include <glm/mat4x4.hpp>

#include <vector>

namespace temporal::render_detail {

// One draw of one primitive instance in this frame.
struct DrawItem {
  GLuint vao = 0;
  GLsizei index_count = 0;
  glm::mat4 model{1.0f}, prev_model{1.0f};  // identity for deformed instances (world-space vertices)
  glm::mat3 normal_matrix{1.0f};
  int material = -1;
  std::uint32_t id = 0;
  bool clockwise = false;                    // negative-determinant model matrix (glTF 3.7.4)
};

class SceneGpu {
 public:
  SceneGpu(const GlFunctions& gl, const SceneGeometry& scene, bool mipmaps);
  ~SceneGpu();
  SceneGpu(const SceneGpu&) = delete;
  SceneGpu& operator=(const SceneGpu&) = delete;

  Status upload();
  // Builds the draw list of `current`, uploading deformed vertices of both frames. `previous` may be null
  // (no motion: the previous positions are the current ones). Instances are paired by index.
  Status prepare(const FrameState& current, const FrameState* previous);
  const std::vector<DrawItem>& draws() const { return draws_; }
  // World-space bounds of this frame's geometry.
  glm::vec3 frame_min() const { return frame_min_; }
  glm::vec3 frame_max() const { return frame_max_; }

  // Sets the material uniforms of `program` (which must be in use) and binds its texture to unit 0.
  void bind_material(GLuint program, int material) const;
  // Draws every item with `program` (in use); sets u_model, u_prev_model, u_normal_matrix, u_id.
  void draw_all(GLuint program, bool cull) const;

 private:
  struct PrimitiveBuffers {
    GLuint vao = 0, position = 0, normal = 0, uv = 0, index = 0;
    GLsizei count = 0;
    glm::vec3 local_min{0.0f}, local_max{0.0f};
  };
  struct DeformedBuffers {
    GLuint vao = 0, position = 0, normal = 0, prev_position = 0;
    int primitive = -1;
  };
  void setup_vao(GLuint vao, const PrimitiveBuffers& p, GLuint position, GLuint normal, GLuint prev) const;

  const GlFunctions& gl_;
  SceneGeometry scene_;
  bool mipmaps_;
  std::vector<PrimitiveBuffers> primitives_;
  std::vector<GLuint> textures_;
  std::vector<DeformedBuffers> deformed_;  // by instance index
  std::vector<DrawItem> draws_;
  std::vector<glm::vec3> scratch_;
  glm::vec3 frame_min_{0.0f}, frame_max_{0.0f};
};

}  // namespace temporal::render_detail
