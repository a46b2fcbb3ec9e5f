// Procedural meshes and textures of the built-in scenes.
#include "shapes.h"

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>

namespace scenegen {
namespace {

constexpr float kPi = 3.14159265358979f;

void push_quad(MeshData& m, glm::vec3 p0, glm::vec3 p1, glm::vec3 p2, glm::vec3 p3, glm::vec3 n, float u0, float v0,
               float u1, float v1) {
  const auto b = static_cast<std::uint32_t>(m.positions.size());
  m.positions.insert(m.positions.end(), {p0, p1, p2, p3});
  m.normals.insert(m.normals.end(), {n, n, n, n});
  m.texcoords.insert(m.texcoords.end(), {{u0, v1}, {u1, v1}, {u1, v0}, {u0, v0}});
  m.indices.insert(m.indices.end(), {b, b + 1, b + 2, b, b + 2, b + 3});
}

std::uint8_t to8(float v) { return static_cast<std::uint8_t>(std::clamp(v, 0.0f, 1.0f) * 255.0f + 0.5f); }

// Texel (x, y) of t, opaque, colour c.
void set_texel(TextureDesc& t, int x, int y, glm::vec3 c) {
  std::uint8_t* p = &t.rgba[static_cast<std::size_t>((y * t.width + x) * 4)];
  p[0] = to8(c.r);
  p[1] = to8(c.g);
  p[2] = to8(c.b);
  p[3] = 255;
}

// A size x size texture, every texel opaque with colour(x, y).
template <typename Colour>
TextureDesc painted(const std::string& name, int size, Colour&& colour) {
  TextureDesc t{name, size, size, {}, true, false};
  t.rgba.resize(static_cast<std::size_t>(size * size * 4));
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) set_texel(t, x, y, colour(x, y));
  return t;
}

}  // namespace

MeshData box(const glm::vec3& size, int segments_y) {
  MeshData m;
  const glm::vec3 h = 0.5f * size;
  // Four sides, split along Y; each quad p0..p3 counter-clockwise seen from outside (bottom-left first).
  const glm::vec3 side_n[4] = {{0, 0, 1}, {1, 0, 0}, {0, 0, -1}, {-1, 0, 0}};
  const glm::vec3 side_a[4] = {{-h.x, 0, h.z}, {h.x, 0, h.z}, {h.x, 0, -h.z}, {-h.x, 0, -h.z}};
  const glm::vec3 side_b[4] = {{h.x, 0, h.z}, {h.x, 0, -h.z}, {-h.x, 0, -h.z}, {-h.x, 0, h.z}};
  for (int s = 0; s < 4; ++s) {
    for (int k = 0; k < segments_y; ++k) {
      const float y0 = -h.y + size.y * static_cast<float>(k) / segments_y;
      const float y1 = -h.y + size.y * static_cast<float>(k + 1) / segments_y;
      const float v0 = 1.0f - static_cast<float>(k + 1) / segments_y, v1 = 1.0f - static_cast<float>(k) / segments_y;
      push_quad(m, side_a[s] + glm::vec3(0, y0, 0), side_b[s] + glm::vec3(0, y0, 0), side_b[s] + glm::vec3(0, y1, 0),
                side_a[s] + glm::vec3(0, y1, 0), side_n[s], 0.0f, v0, 1.0f, v1);
    }
  }
  push_quad(m, {-h.x, h.y, h.z}, {h.x, h.y, h.z}, {h.x, h.y, -h.z}, {-h.x, h.y, -h.z}, {0, 1, 0}, 0, 0, 1, 1);
  push_quad(m, {-h.x, -h.y, -h.z}, {h.x, -h.y, -h.z}, {h.x, -h.y, h.z}, {-h.x, -h.y, h.z}, {0, -1, 0}, 0, 0, 1, 1);
  return m;
}

MeshData cylinder(float radius, float height, int segments, bool caps) {
  MeshData m;
  for (int i = 0; i <= segments; ++i) {
    const float a = 2.0f * kPi * static_cast<float>(i) / segments;
    const glm::vec3 n(std::sin(a), 0.0f, std::cos(a));
    const float u = static_cast<float>(i) / segments;
    m.positions.insert(m.positions.end(), {radius * n, radius * n + glm::vec3(0, height, 0)});
    m.normals.insert(m.normals.end(), {n, n});
    m.texcoords.insert(m.texcoords.end(), {{u, 1.0f}, {u, 0.0f}});
  }
  for (int i = 0; i < segments; ++i) {
    const auto b = static_cast<std::uint32_t>(2 * i);
    m.indices.insert(m.indices.end(), {b, b + 2, b + 3, b, b + 3, b + 1});
  }
  if (caps) {
    for (int cap = 0; cap < 2; ++cap) {
      const float y = cap ? height : 0.0f;
      const glm::vec3 n(0.0f, cap ? 1.0f : -1.0f, 0.0f);
      const auto c = static_cast<std::uint32_t>(m.positions.size());
      m.positions.push_back({0, y, 0});
      m.normals.push_back(n);
      m.texcoords.push_back({0.5f, 0.5f});
      for (int i = 0; i <= segments; ++i) {
        const float a = 2.0f * kPi * static_cast<float>(i) / segments;
        m.positions.push_back({radius * std::sin(a), y, radius * std::cos(a)});
        m.normals.push_back(n);
        m.texcoords.push_back({0.5f + 0.5f * std::sin(a), 0.5f + 0.5f * std::cos(a)});
      }
      for (int i = 0; i < segments; ++i) {
        const auto a = c + 1 + static_cast<std::uint32_t>(i);
        if (cap) m.indices.insert(m.indices.end(), {c, a, a + 1});
        else m.indices.insert(m.indices.end(), {c, a + 1, a});
      }
    }
  }
  return m;
}

MeshData cone(float radius, float height, int segments) {
  MeshData m;
  const float slope = radius / height;
  for (int i = 0; i < segments; ++i) {
    const float a0 = 2.0f * kPi * static_cast<float>(i) / segments, a1 = 2.0f * kPi * static_cast<float>(i + 1) / segments;
    const float am = 0.5f * (a0 + a1);
    const auto b = static_cast<std::uint32_t>(m.positions.size());
    m.positions.insert(m.positions.end(), {{radius * std::sin(a0), 0, radius * std::cos(a0)},
                                           {radius * std::sin(a1), 0, radius * std::cos(a1)},
                                           {0, height, 0}});
    for (float a : {a0, a1, am}) m.normals.push_back(glm::normalize(glm::vec3(std::sin(a), slope, std::cos(a))));
    m.texcoords.insert(m.texcoords.end(), {{static_cast<float>(i) / segments, 1}, {static_cast<float>(i + 1) / segments, 1}, {0.5f, 0}});
    m.indices.insert(m.indices.end(), {b, b + 1, b + 2});
  }
  return m;
}

MeshData plane(float size, float uv_repeat, int n) {
  MeshData m;
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) {
      const float u = static_cast<float>(i) / n, v = static_cast<float>(j) / n;
      m.positions.push_back({(u - 0.5f) * size, 0.0f, (v - 0.5f) * size});
      m.normals.push_back({0, 1, 0});
      m.texcoords.push_back({u * uv_repeat, v * uv_repeat});
    }
  }
  const auto row = static_cast<std::uint32_t>(n + 1);
  for (std::uint32_t j = 0; j < static_cast<std::uint32_t>(n); ++j) {
    for (std::uint32_t i = 0; i < static_cast<std::uint32_t>(n); ++i) {
      const std::uint32_t a = j * row + i;
      // Counter-clockwise seen from +Y: (x, z) -> (x, z + 1) -> (x + 1, z + 1).
      m.indices.insert(m.indices.end(), {a, a + row, a + row + 1, a, a + row + 1, a + 1});
    }
  }
  return m;
}

MeshData quad(float width, float height) {
  MeshData m;
  const float w = 0.5f * width, h = 0.5f * height;
  push_quad(m, {-w, -h, 0}, {w, -h, 0}, {w, h, 0}, {-w, h, 0}, {0, 0, 1}, 0, 0, 1, 1);
  return m;
}

float hash01(std::uint32_t a, std::uint32_t b) {
  std::uint32_t h = a * 0x9E3779B1u ^ (b + 0x7F4A7C15u) * 0x85EBCA77u;
  h ^= h >> 16;
  h *= 0x7FEB352Du;
  h ^= h >> 15;
  h *= 0x846CA68Bu;
  h ^= h >> 16;
  return static_cast<float>(h >> 8) / 16777216.0f;
}

TextureDesc checker(const std::string& name, int size, int squares, glm::vec3 a, glm::vec3 b) {
  return painted(name, size, [&](int x, int y) {
    const bool odd = ((x * squares / size) + (y * squares / size)) % 2 != 0;
    return odd ? a : b;
  });
}

TextureDesc bricks(const std::string& name, int size, int rows, glm::vec3 brick, glm::vec3 mortar) {
  const int bh = size / rows, bw = 2 * bh;
  return painted(name, size, [&](int x, int y) {
    const int row = y / bh;
    const int xs = x + (row % 2) * (bw / 2);
    const int col = (xs / bw) % (size / bw);
    const bool line = (y % bh) < 2 || (xs % bw) < 2;
    const float tint = 0.8f + 0.35f * hash01(static_cast<std::uint32_t>(row), static_cast<std::uint32_t>(col));
    return line ? mortar : brick * tint;
  });
}

TextureDesc leaves(const std::string& name, int size, int count) {
  TextureDesc t{name, size, size, {}, true, false};
  t.rgba.assign(static_cast<std::size_t>(size * size * 4), 0);
  // Dark green where no leaf covers (alpha 0): mipmapped cut-outs then fade to green, not black.
  for (std::size_t i = 0; i < t.rgba.size(); i += 4) {
    t.rgba[i] = 40;
    t.rgba[i + 1] = 80;
    t.rgba[i + 2] = 30;
  }
  for (int k = 0; k < count; ++k) {
    const float cx = (0.1f + 0.8f * hash01(static_cast<std::uint32_t>(k), 1)) * size;
    const float cy = (0.1f + 0.8f * hash01(static_cast<std::uint32_t>(k), 2)) * size;
    const float len = (0.06f + 0.06f * hash01(static_cast<std::uint32_t>(k), 3)) * size;
    const float wid = 0.35f * len;
    const float ang = 6.2831853f * hash01(static_cast<std::uint32_t>(k), 4);
    const float shade = 0.6f + 0.4f * hash01(static_cast<std::uint32_t>(k), 5);
    const float ca = std::cos(ang), sa = std::sin(ang);
    const int r = static_cast<int>(len) + 1;
    for (int y = std::max(0, static_cast<int>(cy) - r); y < std::min(size, static_cast<int>(cy) + r); ++y) {
      for (int x = std::max(0, static_cast<int>(cx) - r); x < std::min(size, static_cast<int>(cx) + r); ++x) {
        const float dx = x + 0.5f - cx, dy = y + 0.5f - cy;
        const float u = (ca * dx + sa * dy) / len, v = (-sa * dx + ca * dy) / wid;
        if (u * u + v * v > 1.0f) continue;
        const float vein = std::fabs(v) < 0.08f ? 0.75f : 1.0f;
        set_texel(t, x, y, glm::vec3(0.18f * shade * vein, 0.45f * shade * vein, 0.12f * shade * vein));
      }
    }
  }
  return t;
}

glm::quat look_rotation(const glm::vec3& forward, const glm::vec3& up) {
  const glm::vec3 z = -glm::normalize(forward);  // the node's +Z points backwards
  const glm::vec3 x = glm::normalize(glm::cross(up, z));
  const glm::vec3 y = glm::cross(z, x);
  return glm::normalize(glm::quat_cast(glm::mat3(x, y, z)));
}

void push_quat(std::vector<float>& out, glm::quat q) {
  q = glm::normalize(q);
  if (out.size() >= 4) {
    const std::size_t n = out.size();
    const float dot = out[n - 4] * q.x + out[n - 3] * q.y + out[n - 2] * q.z + out[n - 1] * q.w;
    if (dot < 0.0f) q = -q;
  }
  out.insert(out.end(), {q.x, q.y, q.z, q.w});
}

}  // namespace scenegen
