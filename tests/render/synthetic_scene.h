// Scenes built in code for the renderer tests: a textured ground, a textured box, and a strip whose
// vertices are deformed on the CPU (standing in for skinning), with camera, node and vertex motion that
// can be switched on one at a time. Independent of the glTF loader.
#pragma once

#include "temporal/render/render.h"
#include "temporal/scene/scene.h"

#include <glm/gtc/matrix_transform.hpp>

#include <cmath>
#include <vector>

namespace temporal::test {

struct SyntheticScene {
  std::vector<ScenePrimitive> primitives;
  std::vector<SceneMaterial> materials;
  std::vector<SceneTexture> textures;

  enum Motion : unsigned { kStatic = 0, kCamera = 1, kNode = 2, kDeform = 4 };
  unsigned motion = kStatic;

  SceneGeometry geometry() const {
    SceneGeometry g;
    g.primitives = &primitives;
    g.materials = &materials;
    g.textures = &textures;
    g.bounds_min = glm::vec3(-5.0f, 0.0f, -5.0f);
    g.bounds_max = glm::vec3(5.0f, 2.5f, 5.0f);
    return g;
  }

  static void add_quad(ScenePrimitive& p, glm::vec3 o, glm::vec3 u, glm::vec3 v, glm::vec2 uv_scale) {
    const auto base = std::uint32_t(p.positions.size());
    const glm::vec3 n = glm::normalize(glm::cross(u, v));
    const glm::vec3 corners[4] = {o, o + u, o + u + v, o + v};
    const glm::vec2 uvs[4] = {{0, 0}, {uv_scale.x, 0}, {uv_scale.x, uv_scale.y}, {0, uv_scale.y}};
    for (int i = 0; i < 4; ++i) {
      p.positions.push_back(corners[i]);
      p.normals.push_back(n);
      p.texcoords.push_back(uvs[i]);
    }
    for (std::uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) p.indices.push_back(base + i);
  }

  SyntheticScene() {
    // An 8x8 checker texture (linear values 0.2 / 0.9 when decoded from sRGB 124 / 243).
    SceneTexture checker;
    checker.width = checker.height = 8;
    checker.srgb = true;
    checker.nearest = true;
    for (int y = 0; y < 8; ++y)
      for (int x = 0; x < 8; ++x) {
        const std::uint8_t c = ((x + y) & 1) ? 243 : 124;
        checker.rgba8.insert(checker.rgba8.end(), {c, c, c, 255});
      }
    textures.push_back(checker);
    SceneMaterial ground;
    ground.name = "ground";
    ground.base_color_texture = 0;
    SceneMaterial box = ground;
    box.name = "box";
    box.base_color_factor = glm::vec4(1.0f, 0.5f, 0.3f, 1.0f);
    SceneMaterial strip;
    strip.name = "strip";
    strip.base_color_texture = 0;
    strip.base_color_factor = glm::vec4(0.3f, 0.6f, 1.0f, 1.0f);
    strip.double_sided = true;
    materials = {ground, box, strip};

    ScenePrimitive g;  // ground: 10 x 10 at y = 0, facing up, checker cells of 0.625 units
    add_quad(g, {-5, 0, 5}, {10, 0, 0}, {0, 0, -10}, {2, 2});
    g.material = 0;
    ScenePrimitive b;  // unit box centred on the origin, outward normals, CCW from outside
    const glm::vec3 X(1, 0, 0), Y(0, 1, 0), Z(0, 0, 1);
    add_quad(b, {-0.5f, -0.5f, 0.5f}, X, Y, {0.25f, 0.25f});  // +z face
    add_quad(b, {0.5f, -0.5f, -0.5f}, -X, Y, {0.25f, 0.25f});  // -z face
    add_quad(b, {0.5f, -0.5f, 0.5f}, -Z, Y, {0.25f, 0.25f});  // +x face
    add_quad(b, {-0.5f, -0.5f, -0.5f}, Z, Y, {0.25f, 0.25f});  // -x face
    add_quad(b, {-0.5f, 0.5f, 0.5f}, X, -Z, {0.25f, 0.25f});  // +y face
    add_quad(b, {-0.5f, -0.5f, -0.5f}, X, Z, {0.25f, 0.25f});  // -y face
    b.material = 1;
    ScenePrimitive s;  // strip: 16 segments along x, deformed per frame
    for (int i = 0; i <= 16; ++i)
      for (int j = 0; j <= 1; ++j) {
        s.positions.push_back({-2.0f + 0.25f * float(i), 0.0f, float(j) * 0.8f});
        s.normals.push_back({0, 1, 0});
        s.texcoords.push_back({float(i) * 0.0625f, float(j) * 0.25f});
      }
    for (std::uint32_t i = 0; i < 16; ++i) {
      const std::uint32_t a = 2 * i, bb = a + 1, c = a + 2, d = a + 3;
      for (std::uint32_t v : {a, bb, c, c, bb, d}) s.indices.push_back(v);
    }
    s.material = 2;
    s.morphed = true;
    primitives = {g, b, s};
  }

  // The scene at time t (seconds).
  FrameState evaluate(double t) const {
    FrameState f;
    f.time = t;
    const float ft = float(t);
    // Camera: orbits the origin at 0.4 rad/s when kCamera is set.
    const float angle = (motion & kCamera) ? 0.4f * ft : 0.0f;
    const glm::vec3 eye(7.0f * std::sin(angle), 3.5f, 7.0f * std::cos(angle));
    f.camera.view = glm::lookAt(eye, glm::vec3(0.0f, 0.5f, 0.0f), glm::vec3(0, 1, 0));
    f.camera.yfov = 0.8f;
    f.camera.znear = 0.1f;
    f.camera.zfar = 50.0f;
    f.camera.name = "synthetic";
    LightState key;
    key.type = LightState::Type::Directional;
    key.direction = glm::normalize(glm::vec3(-0.4f, -1.0f, -0.3f));
    key.intensity = 3.0f;
    f.lights.push_back(key);

    PrimitiveInstance ground;
    ground.primitive = 0;
    ground.id = 1;
    f.instances.push_back(ground);

    PrimitiveInstance box;
    box.primitive = 1;
    box.id = 2;
    const float bx = (motion & kNode) ? -1.5f + 1.2f * ft : 0.0f;
    const float spin = (motion & kNode) ? 0.8f * ft : 0.3f;
    box.model = glm::rotate(glm::translate(glm::mat4(1.0f), glm::vec3(bx, 0.9f, 0.5f)), spin, glm::vec3(0, 1, 0));
    f.instances.push_back(box);

    PrimitiveInstance strip;
    strip.primitive = 2;
    strip.id = 3;
    strip.deformed = true;
    const ScenePrimitive& sp = primitives[2];
    const float phase = (motion & kDeform) ? 3.0f * ft : 0.0f;
    for (std::size_t v = 0; v < sp.positions.size(); ++v) {
      const glm::vec3 p = sp.positions[v];
      // A travelling wave lifts the strip; it sits in front of the box, above the ground.
      const float y = 0.6f + 0.35f * std::sin(1.7f * p.x + phase);
      const float dy = 0.35f * 1.7f * std::cos(1.7f * p.x + phase);
      strip.world_positions.push_back({p.x, y, p.z + 1.6f});
      strip.world_normals.push_back(glm::normalize(glm::vec3(-dy, 1.0f, 0.0f)));
    }
    f.instances.push_back(strip);
    return f;
  }
};

}  // namespace temporal::test
