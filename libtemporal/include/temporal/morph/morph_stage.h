// morph-120hz as a stage of the sequence runner (temporal/io/runner.h): the per-frame policy of the tool, in
// the library. The runner owns the loop (patterns, frame list, G-buffer checks, non-finite counting, header
// stamping, atomic writes); the stage adds what is particular to frame-rate conversion:
//  - input frame n becomes output frames n*factor + k, k = 0..factor-1, with temporal:fps = fps*factor and
//    temporal:time = (n*factor + k) / (fps*factor); fps is --fps or the input header's temporal:fps;
//  - slots k >= 1 drop the rendered frame's camera matrices, jitter and camera cut (they do not describe an
//    extrapolated frame); every slot records method, latencyFrames (output frames: the method's rendered
//    frames of latency times factor), sourceFrame, slot and the flow / morph /
//    blur timings (seed 004 Table 1);
//  - methods with lookahead (blend) see frame n+1 of the selected frames (the last one repeats);
//  - NaN and Inf input values (counted and reported by the runner) are replaced by 0 before a method sees them;
//  - the eye-tracking limit's pixels per degree comes from the viewing geometry and the image width;
//  - `perceive`: instead of upsampling, the hold-type blur simulation of temporal/morph/hold_blur.h, whose window
//    of displayed frames reads past the selected frames while files exist (the eye keeps integrating); with a
//    lag reference, the lag apart from the blur (align_lag).
#pragma once

#include "temporal/core/error.h"
#include "temporal/core/params.h"
#include "temporal/core/stage.h"
#include "temporal/morph/hold_blur.h"
#include "temporal/morph/morph.h"

#include <functional>
#include <memory>
#include <string>

namespace temporal::morph {

// Where the viewer sits: the eye-tracking limit of didyk (seed 004 section 6) needs pixels per degree. Defaults:
// the paper's display (Samsung 2233RZ, 0.473 m wide, 1680 pixels) seen from 0.6 m, images shown 1:1.
struct ViewingOptions {
  bool tracking_limit = true;    // false: no eye-tracking damping of the vertex motion
  float ppd = 0.0f;              // pixels per degree; 0 derives it from the three fields below
  float screen_width_m = 0.473f; // screen width, metres
  float distance_m = 0.6f;       // viewing distance, metres
  int pixels_x = 1680;           // pixels across the screen; 0: the image fills the screen width
};

// Pixels per degree for an image `image_width` pixels wide under `viewing`; 0 when the limit is off.
float tracking_pixels_per_degree(const ViewingOptions& viewing, int image_width);

// Everything morph-120hz does beyond the sequence options (temporal/io/runner.h). The defaults here are the
// tool's defaults (the command line binds to these fields through morph_stage_params()).
struct MorphStageOptions {
  MorphOptions morph;    // the method and its parameters
  // The three colour channels morphed (select_layers, temporal/core/image.h: rgb, or a layer such as `direct`
  // with direct.R, G, B); the outputs keep their names. --perceive reads rgb only.
  std::string layer = "rgb";
  double fps = 0.0;      // input frame rate; 0 reads temporal:fps from each input header
  std::string display;   // display colour space whose gamma replaces morph.gamma (empty: none)
  std::string ocio;      // OpenColorIO config for `display` (empty: $OCIO, else the built-in one)
  ViewingOptions viewing;
  bool perceive = false;  // simulate hold-type blur instead of upsampling
  HoldBlurOptions hold;   // perceive: the eye's window
  // perceive: the perceived images of the reference (native) stream, PATTERN.####.exr. When set, each frame t is
  // also aligned to the reference's perceived frame t by the best shift tau along the motion (align_lag,
  // hold_blur.h): layer `aligned.R,G,B`; headers temporal:lagContentFrames (tau), temporal:lagFrames (tau + L,
  // L = the input's temporal:latencyFrames, known exactly and so added, not searched) and temporal:lagMs.
  std::string lag_reference;
  LagSearchOptions lag;
};

// Every parameter of the tool: those of MorphOptions (params(), temporal/morph/methods.h: the method, factor,
// gamma, debug layers, each registered method's own), then the input rate, the display and viewing geometry,
// perceive and its window.
ParamList morph_stage_params(MorphStageOptions& options);

// The file and colour-management services the stage needs for two options, given by the caller so that the
// morph stage links no image or colour library (the tool passes the io stage's read_exr and ColorConfig):
//  - read_rgb: the R,G,B of one image file (the --lag-reference frames);
//  - display_gamma: the power-law exponent of a display colour space in an OpenColorIO config (--display).
struct MorphStageIO {
  std::function<Expected<Image>(const std::string& path)> read_rgb;
  std::function<Expected<float>(const std::string& display, const std::string& ocio_config)> display_gamma;
};

// The stage for these options. Errors (before any frame is read): Usage for invalid options (unknown method,
// factor < 2, a grid that is not a power of two), the colour config's errors for `display`; Usage when an
// option needs a service that `io` lacks.
Expected<std::unique_ptr<FrameStage>> make_morph_stage(const MorphStageOptions& options, const MorphStageIO& io = {});

}  // namespace temporal::morph
