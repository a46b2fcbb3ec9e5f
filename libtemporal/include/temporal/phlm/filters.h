// The methods of `filter-phlm` as units, in the pattern every stage shares (temporal/core/method.h): each method's
// source file (src/phlm/phlm.cpp, taa.cpp, ema.cpp, fxaa.cpp) defines its MethodEntry (what it is, its own
// parameters with their defaults, the G-buffer layers it reads, its implementations), and src/phlm/registry.cpp
// lists the entries, one line each. Adding a method is one source file, its line in registry.cpp and its section in
// docs/filter-phlm.md: no public header, no field here. The tool binds every method's parameters to its command
// line from here (params()), prints --list-methods(-json) from registry(), and runs the chosen method through the
// sequence runner (temporal/io/runner.h).
#pragma once

#include "temporal/core/method.h"
#include "temporal/core/params.h"
#include "temporal/core/stage.h"
#include "temporal/phlm/frame_filter.h"

#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace temporal::phlm {

// Every registered method's own parameters, with their defaults.
MethodOptionSet default_method_options();

// Every option of filter-phlm: the method, the layer, debug layers, and each method's own parameters.
struct FilterOptions {
  std::string method = "phlm";  // a name of the registry
  std::string layer = "rgb";    // rgb (R,G,B) or a layer name (ssao, shadow, direct, ...)
  std::string device = "cpu";   // the implementation's device: "cpu" or "gpu" (temporal/core/method.h)
  bool debug_layers = false;
  MethodOptionSet per_method = default_method_options();
};

// A method's filter for these (checked) options, on one device: a CPU factory
// `std::unique_ptr<FrameFilter> (const FilterOptions&)` or a GPU one
// `Expected<std::unique_ptr<FrameFilter>> (std::shared_ptr<gpu::Context>, const FilterOptions&)` (wrapping
// temporal/phlm/gpu_filters.h), listed as `{kGpuDevice, ...}` in the method's entry: --device picks it
// (temporal/core/method.h, DeviceFactory).
using FilterFactory = DeviceFactory<FrameFilter, const FilterOptions&>;

// One method of filter-phlm.
struct MethodEntry {
  MethodInfo info;  // name (--method), summary, has_state (false: spatial, no --state-in / --state-out)
  // The method's own parameters with their defaults (nullptr: none).
  std::unique_ptr<MethodOptions> (*make_options)() = nullptr;
  // G-buffer layers it reads when --gbuffer is given (motion always; EMA also depth and id).
  std::vector<LayerNeed> (*layers)(const FilterOptions&) = nullptr;
  // Its implementations, per device ("cpu", "gpu").
  std::vector<Implementation<FilterFactory>> implementations = {};
};

// The registry, in the order of the docs, --help and --list-methods.
const std::vector<const MethodEntry*>& registry();
// The method called `name`, or nullptr.
const MethodEntry* find_entry(std::string_view name);
// Every method with its defaults followed by its named variants, in table order.
const std::vector<MethodVariant>& method_variants();
// The variant (or plain method) called `name`, or nullptr.
const MethodVariant* find_variant(std::string_view name);

// Every parameter of the tool, pointing at the fields of `options`: --method, --layer, --debug-layers, then each
// method's own (help prefixed with the method's name). Valid while `options` lives and is not moved.
ParamList params(FilterOptions& options);
// Usage error unless the method exists and every parameter is valid.
Status check(const FilterOptions& options);
// Options for `method` with parameters set by command-line style arguments, e.g. make_options("taa",
// {"--taa-clip", "minmax"}). Usage error for an unknown method or parameter, or an invalid value.
Expected<FilterOptions> make_options(const std::string& method, const std::vector<std::string>& args = {});
// The filter of options.method with its parameters on options.device (check() first). On the GPU it runs in
// `context`, or in a new context on the default EGL device when `context` is null (a usage error naming the fix
// when none can be made).
Expected<std::unique_ptr<FrameFilter>> make_filter(const FilterOptions& options,
                                                   std::shared_ptr<gpu::Context> context = nullptr);

// The runner stage of filter-phlm (temporal/io/runner.h): selects the layer's channels of each frame, feeds the
// method with the frame's motion (and depth and ids), times it and saves / resumes its state. Usage error for an
// unknown method or invalid parameters.
Expected<std::unique_ptr<FrameStage>> make_filter_stage(const FilterOptions& options);

}  // namespace temporal::phlm
