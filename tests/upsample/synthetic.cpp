#include "synthetic.h"

#include "temporal/core/jitter.h"

#include <cmath>

namespace temporal::test {

float background_payload(const SyntheticScene& s, float u, float v, int c) {
  const float w = 6.2831853f / s.period;
  const float base = 0.5f + s.amplitude * std::sin(w * u) * std::cos(0.8f * w * v) + s.payload_offset;
  return c == 0 ? base : c == 1 ? 0.6f * base + 0.1f : 0.25f + (s.amplitude / 3.0f) * std::cos(0.5f * w * (u + v)) + s.payload_offset;
}

namespace {
float object_payload(const SyntheticScene& s, float u, float v, int c) {
  // A different, also smooth, material: dark with a gentle ramp.
  return (c == 0 ? 0.05f : c == 1 ? 0.9f : 0.1f) + 0.002f * (u + v) + s.payload_offset;
}
}  // namespace

SyntheticFrame make_frame(const SyntheticScene& s, int frame) {
  SyntheticFrame f;
  const int W = s.width, H = s.height, k = s.k;
  f.gbuffer = Image(W, H);
  float* z = f.gbuffer.add_channel("depth.Z");
  float* nx = f.gbuffer.add_channel("N.X");
  float* ny = f.gbuffer.add_channel("N.Y");
  float* nz = f.gbuffer.add_channel("N.Z");
  float* mx = f.gbuffer.add_channel("motion.X");
  float* my = f.gbuffer.add_channel("motion.Y");
  std::uint32_t* id = f.gbuffer.add_uint_channel("id");
  f.reference = Image(W, H);
  float* ref[3] = {f.reference.add_channel("R"), f.reference.add_channel("G"), f.reference.add_channel("B")};
  f.object_mask = Image(W, H);
  float* mask = f.object_mask.add_channel("mask");
  const glm::vec2 cam = s.camera_velocity * float(frame);
  const glm::vec2 obj = s.object_start + s.object_velocity * float(frame);
  for (int Y = 0; Y < H; ++Y)
    for (int X = 0; X < W; ++X) {
      const std::size_t i = std::size_t(Y) * W + X;
      const float px = X + 0.5f, py = Y + 0.5f;
      const bool in_obj = s.object && px >= obj.x && px < obj.x + s.object_size && py >= obj.y &&
                          py < obj.y + s.object_size;
      mask[i] = in_obj ? 1.0f : 0.0f;
      nx[i] = 0.0f;
      ny[i] = 0.0f;
      nz[i] = 1.0f;
      if (in_obj) {
        z[i] = s.object_depth;
        id[i] = 2;
        // p_prev = p + motion: the square was at obj - velocity.
        mx[i] = frame > 0 ? -s.object_velocity.x : 0.0f;
        my[i] = frame > 0 ? -s.object_velocity.y : 0.0f;
        for (int c = 0; c < 3; ++c) ref[c][i] = object_payload(s, px - obj.x, py - obj.y, c);
      } else {
        z[i] = s.background_depth;
        id[i] = 1;
        // Surface coordinate u = p + cam(t); at t-1 it was at p + cam(t) - cam(t-1).
        mx[i] = frame > 0 ? s.camera_velocity.x : 0.0f;
        my[i] = frame > 0 ? s.camera_velocity.y : 0.0f;
        for (int c = 0; c < 3; ++c) ref[c][i] = background_payload(s, px + cam.x, py + cam.y, c);
      }
    }
  FrameMetadata& gm = f.gbuffer.metadata();
  gm.near_clip = s.near_clip;
  gm.far_clip = s.far_clip;
  gm.frame = frame;
  gm.fps = 40.0;
  gm.time = frame / 40.0;
  if (frame == 0) gm.camera_cut = true;
  f.reference.metadata() = gm;

  // The regular pattern in its dispersed order (docs/conventions.md "Jitter"), as render-gbuffer renders it.
  const int index = frame % (k * k);
  const glm::ivec2 sub = regular_subpixel(k, index);
  const int sx = sub.x, sy = sub.y;
  f.low = Image(W / k, H / k);
  float* low[3] = {f.low.add_channel("R"), f.low.add_channel("G"), f.low.add_channel("B")};
  for (int y = 0; y < H / k; ++y)
    for (int x = 0; x < W / k; ++x)
      for (int c = 0; c < 3; ++c)
        low[c][std::size_t(y) * (W / k) + x] = ref[c][std::size_t(k * y + sy) * W + (k * x + sx)];
  FrameMetadata lm = gm;
  lm.jitter_factor = k;
  lm.jitter_index = index;
  lm.jitter = glm::vec2((sx + 0.5f) / k - 0.5f, (sy + 0.5f) / k - 0.5f);
  f.low.metadata() = lm;
  return f;
}

}  // namespace temporal::test
