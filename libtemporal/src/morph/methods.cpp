// The registry of morph-120hz's methods (temporal/morph/methods.h), and what is derived from it: the options of
// every method and the parameter list the command line binds.
#include "temporal/morph/methods.h"

namespace temporal::morph {

// Every method, in the order of --help, --list-methods and the docs (didyk first: the default). Adding a method:
// its source file defines `const MethodEntry& NAME_method()` (temporal/core/method.h: info, options, layers,
// implementations, lookahead), and one line X(NAME) in this list declares and registers it.
#define TEMPORAL_MORPH_METHODS(X) \
  X(didyk)  /* didyk.cpp: seed 004 */ \
  X(repeat) /* repeat.cpp */ \
  X(blend)  /* blend.cpp */ \
  X(warp)   /* warp.cpp */ \
  /* a new method: one line above this one */

TEMPORAL_DEFINE_REGISTRY(TEMPORAL_MORPH_METHODS)

ParamList params(MorphOptions& o) {
  ParamList list = {
      Param::choice("--method", "Method (the registry's: morph-120hz --list-methods)", &o.method,
                    method_names(registry())),
      device_param(&o.device),
      Param::integer("--factor", "Output frames per input frame (40 Hz -> 120 Hz: 3)", &o.factor, 2, 32),
      Param::real("--gamma", "Display gamma g of the compensation H' (displayed light = value^g)", &o.gamma, 0.1, 10),
      Param::flag_on("--debug-layers", "Add debug.grid, debug.distortion, debug.blur, debug.H, debug.Hprime (didyk)",
                     &o.debug_layers),
  };
  for (Param& p : method_params(registry(), o.per_method)) list.push_back(std::move(p));
  return list;
}

Expected<MorphOptions> make_options(const std::string& method, const std::vector<std::string>& args) {
  return make_options_with<MorphOptions>(method, args, params, check);
}

std::vector<std::string> morph_gbuffer_channels(const std::string& layer) {
  if (layer == "motion") return {"motion.X", "motion.Y"};
  if (layer == "depth") return {"depth.Z"};
  return {layer};
}

}  // namespace temporal::morph
