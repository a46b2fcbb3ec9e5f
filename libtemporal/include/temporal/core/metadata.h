// Per-frame metadata carried in every EXR header the tools write (docs/conventions.md, "Metadata").
#pragma once

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>

#include <map>
#include <optional>
#include <string>

namespace temporal {

struct FrameMetadata {
  // OpenEXR standard attributes. Matrices follow OpenEXR's row-vector convention in the file; in memory
  // they are glm (column-vector) matrices: p_camera = world_to_camera * p_world.
  std::optional<glm::mat4> world_to_camera;  // `worldToCamera`
  std::optional<glm::mat4> world_to_ndc;     // `worldToNDC`: projection * view, including this frame's jitter
  std::optional<float> near_clip;            // `clipNear`, world units
  std::optional<float> far_clip;             // `clipFar`, world units

  // Project attributes (prefix `temporal:` in the file).
  std::optional<int> frame;                  // frame number N
  std::optional<double> fps;                 // frames per second of the sequence
  std::optional<double> time;                // seconds, = N / fps
  std::optional<glm::vec2> jitter;           // sample offset in pixels of *this* image, in [-0.5, 0.5)
  std::optional<int> jitter_factor;          // k: this image is 1/k of the G-buffer's resolution per axis
  std::optional<int> jitter_index;           // index in the k*k regular pattern (0 .. k*k-1)
  std::optional<bool> camera_cut;            // history must be discarded at this frame
  std::optional<double> compute_ms;          // compute time of the stage that wrote the file (I/O excluded)
  std::string tool;                          // tool that wrote the file, e.g. "upsample-st 0.1.0"
  std::string parameters;                    // its parameters, as given on the command line
  std::map<std::string, double> timings_ms;  // named pass timings (`temporal:ms:<name>`), e.g. gbuffer, shade
  std::map<std::string, std::string> extra;  // any other string attribute (`temporal:<key>`)
};

}  // namespace temporal
