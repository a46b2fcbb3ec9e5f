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

namespace temporal::morph {

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

// --- Lag apart from blur (docs/morph-120hz.md, "Perceived blur: lag apart") --------------------------------
//
// A method that shows the scene tau display frames late (repeat holds frame n for 2 more frames; blend is shown
// one rendered frame late) gives the tracking eye the image of P_j shifted along the motion: with the scene
// moving at u = -motion pixels per frame and the eye following it (section 3), the retina sees what the native
// stream showed tau frames earlier: displayed frame D(t - tau) on the pursuit path r + (i + s) u gives
//
//     P_method_j(r) = P_native_j(r + tau * u(r)) = P_native_j(r - tau * motion(r))
//
// one scalar tau for every pixel of a frame, because a delay is a property of the display stream, not of a
// surface. Scoring P_method against P_native directly charges that displacement as blur. align_lag finds the
// tau that brings the method's perceived image closest (least squared error over every channel) to the
// reference's, A(r) = P_method(r + tau * motion(r)), and returns A: what remains between A and P_native is
// blur (and other error), tau * 1000 / fps is the lag in milliseconds.

struct LagSearchOptions {
  float max_lag_frames = 8.0f;      // tau is searched in [-max, max] display frames
  float coarse_step = 0.25f;        // first pass: every coarse_step frames
  float fine_step = 1.0f / 32.0f;   // second pass: +-coarse_step around the best, every fine_step frames
};

struct LagAlignment {
  double lag_frames = 0.0;   // tau, display frames (> 0: the method is late)
  double mse = 0.0;          // mean squared error of the aligned image against the reference
  double mse_unaligned = 0.0;  // ... and of the image as perceived (tau = 0)
  Image aligned;             // A(r) = perceived(r + tau * motion(r)), `channels` only
};

// Among equal errors (e.g. no motion anywhere) the smallest |tau| wins, so a static frame has no lag.
// Sampling: the bilinear fetch of temporal/core/reproject.h (edge taps repeated). Errors: sizes differ, a
// channel or the motion is missing, bad options.
Expected<LagAlignment> align_lag(const Image& perceived, const Image& reference, const std::vector<std::string>& channels,
                                 const float* motion_x, const float* motion_y, const LagSearchOptions& options = {});

}  // namespace temporal::morph
