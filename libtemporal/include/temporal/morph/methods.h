// The methods of morph-120hz as units: one registry table lists every method with what it is, what it reads,
// its parameters, its latency and a factory for its state. The tool's --method choices and help, --list-methods,
// the pipeline's method list (pipelines/morph-120hz.sh asks --list-methods) and the benchmark's variants all
// come from this table.
//
// Adding a method: one source file in libtemporal/src/morph/ (a MorphMethod and the function returning its
// MorphMethodInfo), one line in the table of methods.cpp (and its declaration beside it), its section in
// docs/morph-120hz.md.
#pragma once

#include "temporal/core/error.h"
#include "temporal/core/image.h"
#include "temporal/core/params.h"
#include "temporal/morph/morph.h"

#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace temporal {

struct MorphStageOptions;  // temporal/morph/morph_stage.h

// The state of one method (buffers kept between frames; no per-pixel allocation).
class MorphMethod {
 public:
  virtual ~MorphMethod() = default;
  // One rendered frame into its `factor` displayed slots. `out` holds factor images of the colour's size with
  // R,G,B and, with MorphOptions::debug_layers, kMorphDebugLayers (values left from the previous call: a method
  // writes every plane it owns; debug planes it has nothing for must be zero). `gbuffer` has the layers of
  // MorphMethodInfo::gbuffer_layers (null when it lists none); `next` is rendered frame n+1 for methods with
  // lookahead (null at the end of the sequence). Inputs are checked (Morpher::process) and finite. Fills `t`.
  virtual void run(const Image& color, const Image* gbuffer, const Image* next, std::vector<Image>& out,
                   MorphTimings& t) = 0;
  // Whether the last run() succeeded: the C++ methods cannot fail; a GPU method (temporal/morph/gpu_methods.h)
  // reports a driver error here (its outputs are then undefined), and Morpher::process returns it.
  virtual Status run_status() const { return Status::ok(); }
};

// One registry entry.
struct MorphMethodInfo {
  std::string name;     // --method NAME, `temporal:method`
  std::string summary;  // one line for --help and --list-methods
  // G-buffer layers it reads ("motion": motion.X/Y, "depth": depth.Z); empty: it needs no G-buffer.
  std::vector<std::string> gbuffer_layers;
  int lookahead = 0;       // rendered frames after the current one it reads (blend: 1)
  // Rendered frames of display latency it adds (blend: 1). The outputs' `temporal:latencyFrames` is in output
  // (display) frames: latency_frames * factor (docs/conventions.md, "Latency").
  int latency_frames = 0;
  // Its own parameters, bound to fields of the options (defaults live there); null: none. Parameters shared
  // by several methods are listed by each and bound once.
  ParamList (*params)(MorphStageOptions& options) = nullptr;
  // A fresh state for these (checked) options.
  std::unique_ptr<MorphMethod> (*make)(const MorphOptions& options) = nullptr;
};

// Every method, in the order --help lists them (didyk first: the default).
std::span<const MorphMethodInfo> morph_methods();

// The entry called `name`; a usage error listing the known names otherwise.
Expected<const MorphMethodInfo*> find_morph_method(std::string_view name);

// The G-buffer channels of a layer name of MorphMethodInfo::gbuffer_layers ("motion" -> motion.X, motion.Y).
std::vector<std::string> morph_gbuffer_channels(const std::string& layer);

}  // namespace temporal
