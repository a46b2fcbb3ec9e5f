// What didyk.cpp (the C++ reference of record) and didyk_gpu.cpp (its GLSL kernels) share: didyk's own parameters
// and the smooth-step from cell distortion to blur strength (not installed).
#pragma once

#include "temporal/core/error.h"
#include "temporal/core/method.h"
#include "temporal/core/params.h"
#include "temporal/morph/grid_warp.h"
#include "temporal/morph/methods.h"

#include <algorithm>
#include <limits>
#include <memory>
#include <string>

namespace temporal::morph::detail {

// Section 5.1 "Selective Blur": cell distortion x to blur strength, 0 below lo, 1 above hi, cubic between (a step at
// hi when hi <= lo). didyk_gpu.cpp's didyk_smoothstep is the same in GLSL.
inline float smoothstep(float lo, float hi, float x) {
  if (hi <= lo) return x >= hi ? 1.0f : 0.0f;
  const float t = std::clamp((x - lo) / (hi - lo), 0.0f, 1.0f);
  return t * t * (3.0f - 2.0f * t);
}

// didyk's own parameters (the display's gamma and the viewer's pixels per degree are the run's, MorphOptions).
struct DidykOptions {
  GridOptions grid;         // cell size and snapping (the eye-tracking limit's fields come from MorphOptions)
  float blur_level = 2.0f;  // pyramid level read for the low-pass layer L (fractional allowed)
  // Smooth-step from cell distortion to blur strength of the in-between frames: 0 below distortion_low,
  // 1 above distortion_high (section 5.1, "Selective Blur").
  float distortion_low = 0.05f;
  float distortion_high = 0.5f;
  float min_blur = 0.0f;   // blur strength floor in [0, 1] (1: blur every in-between frame fully, as [CKL*05])
  bool compensate = true;  // high-frequency compensation of the rendered frame (section 5.1)

  ParamList params() {
    return {
        Param::integer("--grid", "Grid cell size in pixels, a power of two (seed 004: 8)", &grid.cell, 2, 32),
        Param::real("--snap-threshold", "Smallest motion difference (px per input frame) a vertex snaps to",
                    &grid.snap_threshold, 0, 1e6),
        Param::flag_off("--no-snap", "Keep the grid regular (no snapping to motion discontinuities)", &grid.snap),
        Param::real("--blur-level", "Blur pyramid level read for the low-pass layer (fractional allowed)", &blur_level,
                    0, 8),
        Param::real("--distortion-low", "Cell distortion (fraction of a cell) where the in-between blur starts",
                    &distortion_low, 0, 1e6),
        Param::real("--distortion-high", "Cell distortion where the in-between frame is fully blurred",
                    &distortion_high, 0, 1e6),
        Param::real("--min-blur", "Blur strength floor of the in-between frames (1: blur everywhere, [CKL*05])",
                    &min_blur, 0, 1),
        Param::flag_off("--no-compensation", "Do not add compensating high frequencies to the rendered frame",
                        &compensate),
    };
  }
  // What a range cannot say (the pyramid and the snapping work on power-of-two cells).
  Status check() const {
    const int c = grid.cell;
    if (c < 2 || c > 32 || (c & (c - 1)) != 0)
      return Error::usage("--grid must be a power of two from 2 to 32 (got " + std::to_string(c) + ")");
    if (!(blur_level >= 0.0f && blur_level <= 8.0f)) return Error::usage("--blur-level must be in [0, 8]");
    return Status::ok();
  }
};

}  // namespace temporal::morph::detail
