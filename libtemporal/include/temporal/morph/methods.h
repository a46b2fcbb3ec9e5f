// The methods of morph-120hz as units, in the pattern every stage shares (temporal/core/method.h): each method's
// source file (src/morph/didyk.cpp, repeat.cpp, blend.cpp, warp.cpp) defines its MethodEntry (what it is, its own
// parameters with their defaults, the G-buffer layers it reads, its lookahead and latency, its implementations), and
// src/morph/methods.cpp lists the entries, one line each. The tool's --method choices and help, --list-methods and
// --list-methods-json, the pipeline's method list (pipelines/morph-120hz.sh asks --list-methods) and the
// benchmark's variants all come from this table.
//
// Adding a method: one source file in libtemporal/src/morph/ (a MorphMethod and the function returning its
// MethodEntry), its line in methods.cpp, its section in docs/morph-120hz.md.
#pragma once

#include "temporal/core/error.h"
#include "temporal/core/image.h"
#include "temporal/core/method.h"
#include "temporal/core/params.h"
#include "temporal/core/stage.h"
#include "temporal/morph/morph.h"

#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace temporal::morph {

// The state of one method (buffers kept between frames; no per-pixel allocation).
class MorphMethod {
 public:
  virtual ~MorphMethod() = default;
  // One rendered frame into its `factor` displayed slots. `out` holds factor images of the colour's size with
  // R,G,B and, with MorphOptions::debug_layers, kMorphDebugLayers (values left from the previous call: a method
  // writes every plane it owns; debug planes it has nothing for must be zero). `gbuffer` has the layers of the
  // entry's layers() (null when it lists none); `next` is rendered frame n+1 for methods with lookahead (null at
  // the end of the sequence). Inputs are checked (Morpher::process) and finite. Fills `t`.
  virtual void run(const Image& color, const Image* gbuffer, const Image* next, std::vector<Image>& out,
                   MorphTimings& t) = 0;
  // Whether the last run() succeeded: the C++ methods cannot fail; a GPU method (temporal/morph/gpu_methods.h)
  // reports a driver error here (its outputs are then undefined), and Morpher::process returns it.
  virtual Status run_status() const { return Status::ok(); }
};

// A method's state for these (checked) options, on one device: a CPU factory
// `std::unique_ptr<MorphMethod> (const MorphOptions&)` or a GPU one
// `Expected<std::unique_ptr<MorphMethod>> (std::shared_ptr<gpu::Context>, const MorphOptions&)`
// (temporal/morph/gpu_methods.h), listed as `{kGpuDevice, make_NAME_method_gpu}` in the method's entry: --device
// picks it (temporal/core/method.h, DeviceFactory).
using MethodFactory = DeviceFactory<MorphMethod, const MorphOptions&>;

// One registry entry.
struct MethodEntry {
  // name (--method, `temporal:method`), summary, and latency_frames: the rendered frames of display latency it
  // adds (blend: 1; every entry sets it). The outputs' `temporal:latencyFrames` is in output (display) frames:
  // latency_frames * factor (docs/conventions.md, "Latency").
  MethodInfo info;
  // The method's own parameters with their defaults (nullptr: none).
  std::unique_ptr<MethodOptions> (*make_options)() = nullptr;
  // G-buffer layers it reads ("motion": motion.X/Y, "depth": depth.Z); none: it needs no G-buffer.
  std::vector<LayerNeed> (*layers)(const MorphOptions&) = nullptr;
  // Its implementations, per device ("cpu", "gpu").
  std::vector<Implementation<MethodFactory>> implementations = {};
  int lookahead = 0;  // rendered frames after the current one it reads (blend: 1)
};

// Every method, in the order --help lists them (didyk first: the default).
const std::vector<const MethodEntry*>& registry();
// The method called `name`, or nullptr.
const MethodEntry* find_entry(std::string_view name);
// Every method with its defaults followed by its named variants, in table order.
const std::vector<MethodVariant>& method_variants();
// The variant (or plain method) called `name`, or nullptr.
const MethodVariant* find_variant(std::string_view name);

// The parameters of MorphOptions, pointing at its fields: --method (the registry's names), --factor, --gamma,
// --debug-layers, then each method's own (help prefixed with the method's name). Valid while `options` lives and is
// not moved.
ParamList params(MorphOptions& options);
// Options for `method` with parameters set by command-line style arguments, e.g. make_options("didyk",
// {"--no-snap"}). Usage error for an unknown method or parameter, or invalid values (check()).
Expected<MorphOptions> make_options(const std::string& method, const std::vector<std::string>& args = {});

// The G-buffer channels of a layer name of an entry's layers ("motion" -> motion.X, motion.Y).
std::vector<std::string> morph_gbuffer_channels(const std::string& layer);

}  // namespace temporal::morph
