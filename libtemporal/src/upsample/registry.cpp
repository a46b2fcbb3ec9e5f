// The methods of the upsampling stage, as one table, and what is derived from it: the options of every method,
// the parameter list the command line binds, the G-buffer layers, the variants of the benchmark and pipelines.
#include "method.h"

#include <algorithm>
#include <limits>

namespace temporal::upsample {
namespace {
}  // namespace

// Every method, in the order of --help, --list-methods and the docs. Adding a method: its source file defines
// `const MethodEntry& NAME_method()` (temporal/core/method.h: info, options, layers, implementations, streamed
// bytes), and one line X(NAME) in this list declares and registers it.
#define TEMPORAL_UPSAMPLE_METHODS(X) \
  X(spatial)  /* spatial.cpp: seed 000 section 3.1 */ \
  X(temporal) /* temporal.cpp: seed 000 section 3.2 */ \
  X(herzog)   /* herzog.cpp: seed 000 */ \
  X(drobot)   /* drobot.cpp: seed 002 */ \
  X(taau)     /* taau.cpp */ \
  /* a new method: one line above this one */

TEMPORAL_DEFINE_REGISTRY(TEMPORAL_UPSAMPLE_METHODS)

const std::vector<VariantSuffix>& variant_suffixes() {
  static const std::vector<VariantSuffix> list = {
      {"-demod", {"--demodulate"}, "any method on the demodulated lighting (seed 000 section 4, shader splitting)"}};
  return list;
}

// --- Options --------------------------------------------------------------------------------------------------

ParamList params(Options& o) {
  ParamList list = {
      Param::choice("--method", "Upsampling method (upsample-st --list-methods describes each)", &o.method,
                    method_names(registry())),
      Param::text("--layer", "Payload layers to upsample: rgb (bare R,G,B) or layer names, comma-separated", &o.layer),
      device_param(&o.device),
      Param::flag_on("--debug-layers",
                     "Add debug.* layers: confidence, disocclusion, gradient, wf, historyWeight, convergence",
                     &o.debug_layers),
      Param::real("--sigma-normal", "sigma_n of the normal weight (seed 000 eq. 2)", &o.sigma_normal, 1e-3, 1e3),
      Param::real("--sigma-depth-fraction", "sigma_d as a fraction of clipFar - clipNear (seed 000 section 3.1: 3%)",
                  &o.sigma_depth_fraction, 1e-6, 1.0),
      Param::real_or_zero("--sigma-depth", "Absolute sigma_d in world units; 0 uses --sigma-depth-fraction", &o.sigma_depth,
                  1e-6, 1e6),
      Param::real("--depth-tolerance",
                  "Relative depth difference above which a history tap is disoccluded (temporal/core/reproject.h)",
                  &o.depth_tolerance, 0.0, 10.0),
      Param::real("--warped-depth-tolerance",
                  "Relative depth tolerance when the G-buffer has prevDepth.Z (the warped depth of seed 000 section 3.2)",
                  &o.warped_depth_tolerance, 0.0, 10.0),
      Param::flag_on("--no-depth-velocity",
                     "Ignore the G-buffer's prevDepth.Z: compare the current depth at --depth-tolerance (ablation)",
                     &o.no_depth_velocity),
      Param::flag_on("--no-ids", "Disocclusion test on depth only (no material-id comparison, seed 000 Figure 3)",
                     &o.no_ids),
  };
  for (Param& p : method_params(registry(), o.per_method)) list.push_back(std::move(p));
  list.push_back(Param::flag_on("--demodulate",
                                "Upsample lighting only: divide R,G,B by the G-buffer albedo, multiply the result "
                                "back (seed 000 section 4); needs `albedo` in the G-buffer",
                                &o.demodulate));
  list.push_back(Param::integer("--aa-factor",
                                "Antialiasing variant (seed 000 section 4): the G-buffer is m x m the output "
                                "resolution; the result is box-downsampled by m",
                                &o.aa_factor, 1, 8));
  return list;
}

Status check(const Options& options) { return check_stage_options(registry(), options, params); }

Expected<Options> make_options(const std::string& method, const std::vector<std::string>& args) {
  return make_options_with<Options>(method, args, params, check);
}

std::string method_parameters(const Options& o) {
  Options copy = o;  // params() points at the fields it is given
  MethodOptions* m = copy.per_method.find(o.method);
  if (!m) return {};
  std::string text;
  for (const Param& p : m->params()) {
    const std::string value = param_value_text(p);
    const bool flag = std::holds_alternative<bool*>(p.value);
    if (flag && value != "on") continue;
    text += (text.empty() ? "" : " ") + p.flag;
    if (!flag) text += " " + value;
  }
  return text;
}

std::vector<std::string> gbuffer_layers(const Options& o) {
  std::vector<std::string> layers;
  if (const MethodEntry* e = find_entry(o.method))
    for (const LayerNeed& n : e->layers(o)) layers.push_back(n.layer);
  if (o.demodulate) layers.push_back("albedo");
  return layers;
}

std::size_t Upsampler::streamed_bytes(const Options& o, int W, int H, int k, int C) {
  const MethodEntry* e = find_entry(o.method);
  return e ? e->streamed_bytes(o, W, H, k, C) : 0;
}

}  // namespace temporal::upsample
