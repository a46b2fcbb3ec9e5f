// Perceived image on a hold-type display under smooth-pursuit eye motion (seed 004 section 3, Figure 1;
// [KV04]'s box-filter model of hold-type blur).
//
// A hold-type display shows frame j for its whole hold time T = 1/fps. An eye that tracks the motion of the
// surface at retinal position r moves with velocity v(r) = -motion(r) pixels per display frame (motion in the
// conventions' sign: p_prev = p + motion, measured at the display rate). Over a window of W displayed
// frames starting at frame j the retina integrates
//
//     P_j(r) = 1/W * sum_{i=0}^{W-1} integral_0^1 D_{j+i}(r + (i + s) * v(r)) ds
//
// in linear light (Bloch's law: energy adds up within the ~40 ms critical duration, so W = 3 frames at
// 120 Hz, 25 ms, is the default). A native high-rate rendering gives a short box blur of |v| pixels; a held
// low-rate frame shown W times gives the long box blur of W*|v| pixels that seed 004 sets out to remove, and
// interleaved sharp/blurred frames integrate to what they sum to. Comparing P_j of a method with P_j of the
// native 120 Hz rendering (same motion field) puts seed 004's user study on a reproducible number.
#pragma once

#include "temporal/core/error.h"
#include "temporal/core/image.h"

#include <span>
#include <string>
#include <vector>

namespace temporal {

struct HoldBlurOptions {
  int window = 3;             // displayed frames integrated by the eye (>= 1)
  int samples_per_pixel = 2;  // integration samples per pixel of travel within one frame (>= 1)
  int max_samples = 64;       // cap on the samples per frame and pixel
};

// Perceived image of frames[0] (the window frames[0 .. W-1]; fewer at the end of a sequence are accepted and
// averaged over what is given). `channels` are float channels present in every frame; motion_x/motion_y are
// the display-rate motion planes of frames[0]'s scene (width x height). Sampling is bilinear, clamped at the
// image border (the bilinear fetch of temporal/core/reproject.h). Errors: no frame, mismatched sizes, missing
// channels.
Expected<Image> perceive_hold(std::span<const Image* const> frames, const std::vector<std::string>& channels,
                              const float* motion_x, const float* motion_y, const HoldBlurOptions& options = {});

}  // namespace temporal
