// What the filters of `filter-phlm` receive for one frame (FilterInput), what they report (FilterStats) and the
// interface every filter implements (FrameFilter). The registry of methods is temporal/phlm/filters.h.
#pragma once

#include "temporal/core/error.h"
#include "temporal/core/image.h"

#include <glm/vec2.hpp>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace temporal::phlm {

// One input frame. Planes are width x height, row-major (the planes of an Image).
struct FilterInput {
  const Image* color = nullptr;       // the frame to filter (scene-linear values)
  std::vector<std::string> channels;  // the channels of `color` to filter: 3 (R,G,B) or 1 (e.g. ssao.Y)
  // Motion in pixels, p_prev = p + motion (docs/conventions.md). Null: static scene (motion 0), seed 003's
  // "special case with static scenes".
  const float* motion_x = nullptr;
  const float* motion_y = nullptr;
  // G-buffer data for the history rejection of `ema` (null: no rejection). Depth: linear view depth.
  const float* depth = nullptr;
  const std::uint32_t* id = nullptr;
  // prevDepth.Z: the depth each pixel's surface point had in the previous frame (null: absent). `ema` compares
  // it, instead of `depth`, with the previous depth (seed 000 section 3.2's warped depth).
  const float* prev_depth = nullptr;
  // `temporal:jitter` of this frame, pixels in [-0.5, 0.5): the sample of pixel (x, y) was taken at
  // (x + 0.5 + jx, y + 0.5 + jy). Used by `taa` to reconstruct pixel centres.
  glm::vec2 jitter{0.0f, 0.0f};
  // Discard every history at this frame (first frame, camera cut, --reset-frames).
  bool reset = false;
  // Write `debug.*` planes into the output image.
  bool debug = false;
};

// Counts of one frame, for the tool's report.
struct FilterStats {
  std::size_t non_finite = 0;       // input pixels with a NaN or Inf value (never entered a history)
  std::size_t history_resets = 0;   // histories / models reset (off-screen, first frame, cut, rejection)
  std::size_t clamped = 0;          // histories clipped or models reset by the neighbourhood box test
  double max_trace_p = 0.0;         // PHLM: largest trace(P) after the update
};

// How a method fetches its history (or PHLM its models) at the fractional position p + motion, through
// temporal/core/reproject.h: the 2x2 bilinear taps, the 4x4 Catmull-Rom taps, or the nearest pixel.
enum class HistoryFetch { Bilinear, CatmullRom, Nearest };
// "bilinear" | "catmull-rom" | "nearest"; a usage error naming `flag` otherwise.
Expected<HistoryFetch> parse_history_fetch(const std::string& name, const char* flag);

// Checks that `in` is usable: a colour image with the named float channels (1 or 3 of them). Input error
// naming the missing channel otherwise.
Status validate_filter_input(const FilterInput& in);

// A temporal (or spatial) filter of one frame at a time. Implementations keep their state between calls: pass the
// same `output` image every frame to avoid allocations.
class FrameFilter {
 public:
  virtual ~FrameFilter() = default;
  // Filters one frame into `output` (same size; channels named like the input's; debug.* planes when in.debug).
  virtual Status process(const FilterInput& in, Image& output, FilterStats* stats = nullptr) = 0;
  // The state after the last frame as named planes, as --state-out writes it; empty before the first frame (and
  // always for a spatial filter: its registry entry says has_state = false, temporal/phlm/filters.h).
  virtual Image saved_state() const = 0;
  // Resumes from a state written by state() (the next frame continues bit for bit). `channels`: 1 or 3.
  virtual Status set_state(const Image& state, int channels) = 0;
  // Extra text for --verbose after a frame (e.g. PHLM's largest trace(P)); empty when none.
  virtual std::string stats_text(const FilterStats& stats) const { return {}; }
};

}  // namespace temporal::phlm
