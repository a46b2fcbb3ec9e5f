// Synthetic G-buffer sequences for the upsampling tests: an analytic payload on a textured background
// plane and an optional foreground square, a camera that pans, a square that moves, subsampled into 1/k
// frames with the regular jitter pattern and the metadata of docs/conventions.md.
#pragma once

#include "temporal/core/image.h"

#include <glm/vec2.hpp>

namespace temporal::test {

struct SyntheticScene {
  int width = 64, height = 48, k = 4;
  glm::vec2 camera_velocity{0.0f, 0.0f};  // pixels per frame: the background texture moves by -velocity
  bool object = false;
  glm::vec2 object_start{8.0f, 12.0f};     // top-left corner at frame 0, pixels
  glm::vec2 object_velocity{0.0f, 0.0f};   // pixels per frame
  int object_size = 20;
  float background_depth = 50.0f, object_depth = 10.0f;
  float near_clip = 0.1f, far_clip = 100.0f;
  float period = 40.0f;                    // spatial period of the background payload, pixels
  float amplitude = 0.3f;
  float payload_offset = 0.0f;             // added to every payload value (scene changes for cut tests)
};

struct SyntheticFrame {
  Image gbuffer;    // depth.Z, N.X/Y/Z, motion.X/Y, id (full resolution)
  Image low;        // R,G,B at 1/k with jitter metadata
  Image reference;  // R,G,B at full resolution
  Image object_mask;  // `mask` channel: 1 where the object is visible
};

// Payload of the background at surface coordinates (u, v), channel c (0..2).
float background_payload(const SyntheticScene& s, float u, float v, int c);

SyntheticFrame make_frame(const SyntheticScene& scene, int frame);

}  // namespace temporal::test
