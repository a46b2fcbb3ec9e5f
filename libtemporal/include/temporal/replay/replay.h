// The render-gbuffer sequence (docs/render-gbuffer.md): which frames a replay covers, and the loop that
// evaluates the scene at frame N and N-1, renders, stamps and writes each output as DIR/<output>.####.exr
// plus one row of DIR/timings.csv. The tool parses options into RenderOptions, SceneLoadOptions and
// ReplayOptions (whose defaults are the documented ones) and reports what this returns.
#pragma once

#include "temporal/core/error.h"
#include "temporal/io/exr.h"
#include "temporal/io/runner.h"
#include "temporal/core/sequence.h"
#include "temporal/render/render.h"
#include "temporal/scene/scene.h"

#include <functional>
#include <optional>
#include <string>

namespace temporal {

struct ReplayOptions {
  std::string out_dir;                                 // created if missing
  double fps = 40.0;                                   // frame N is the scene at t = N / fps seconds
  std::optional<FrameRange> frames;                    // inclusive; else default_frames(fps, duration_s)
  double duration_s = 0.0;                             // > 0: frames 0 .. ceil(duration_s * fps) - 1
  ExrCompression compression = ExrCompression::Zip;    // lossless only: DWA is refused on data layers
  std::string tool, parameters;                        // temporal:tool and temporal:parameters of every file
};

// "zip", "piz", "none" (render-gbuffer --compression).
Expected<ExrCompression> parse_replay_compression(const std::string& name);
const char* compression_name(ExrCompression compression);

// Usage errors: fps not positive, negative frames, frames and duration both given, DWA compression.
Status validate(const ReplayOptions& options);

// The frames the replay renders: `frames` when given, else Scene::default_frames(fps, duration_s).
FrameRange replay_frames(const Scene& scene, const ReplayOptions& options);

// The observers every run has (temporal/io/runner.h): `log` gets what --verbose prints (OpenGL, the frame
// range), `frame_done` is called after each frame's files are written.
using ReplayHooks = RunHooks;

// Renders and writes the sequence. Errors: Usage (options), Internal (OpenGL), Output (folder or file not
// writable). LP_NUM_THREADS must be set before this creates the OpenGL context.
Status replay(const Scene& scene, const RenderOptions& render, const ReplayOptions& options,
              const ReplayHooks& hooks = {});

}  // namespace temporal
