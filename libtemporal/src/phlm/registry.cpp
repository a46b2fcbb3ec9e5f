// The methods of filter-phlm as one table (temporal/phlm/filters.h), and what is derived from it: the options of
// every method, the parameter list the command line binds, the filter of the chosen method.
#include "temporal/phlm/filters.h"

#include "temporal/gpu/device.h"

namespace temporal::phlm {

// Every method, in the order of --help, --list-methods and the docs. Adding a method: its source file defines
// `const MethodEntry& NAME_method()` (temporal/core/method.h: info, options, layers, implementations), and one
// line X(NAME) in this list declares and registers it.
#define TEMPORAL_PHLM_METHODS(X) \
  X(phlm) /* phlm.cpp: seed 003 */ \
  X(taa)  /* taa.cpp */ \
  X(ema)  /* ema.cpp */ \
  X(fxaa) /* fxaa.cpp */ \
  /* a new method: one line above this one */

TEMPORAL_DEFINE_REGISTRY(TEMPORAL_PHLM_METHODS)

ParamList params(FilterOptions& o) {
  ParamList list = {
      Param::choice("--method", "Filter method (filter-phlm --list-methods describes each)", &o.method,
                    method_names(registry())),
      Param::text("--layer", "Layer to filter: rgb (R,G,B) or a layer name (ssao, shadow, direct, ...)", &o.layer),
      device_param(&o.device),
      Param::flag_on("--debug-layers",
                     "Add debug.* layers (phlm: feature, alpha, reset, traceP; taa: clip, noHistory, velocity; ema: "
                     "reject; fxaa: edge)",
                     &o.debug_layers),
  };
  for (Param& p : method_params(registry(), o.per_method)) list.push_back(std::move(p));
  return list;
}

Status check(const FilterOptions& options) { return check_stage_options(registry(), options, params); }

Expected<FilterOptions> make_options(const std::string& method, const std::vector<std::string>& args) {
  return make_options_with<FilterOptions>(method, args, params, check);
}

Expected<std::unique_ptr<FrameFilter>> make_filter(const FilterOptions& options,
                                                   std::shared_ptr<gpu::Context> context) {
  if (Status s = check(options); !s) return s.error();
  const auto* implementation = find_implementation(*find_entry(options.method), options.device);
  if (!implementation)
    return Error::internal("--method " + options.method + " has no " + options.device + " implementation");
  if (options.device == kGpuDevice && !context) {
    auto made = gpu::context_for_device(options.device);
    if (!made) return made.error();
    context = std::move(*made);
  }
  return implementation->make(std::move(context), options);
}

}  // namespace temporal::phlm
