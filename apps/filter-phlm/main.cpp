// filter-phlm: temporal filtering of a 1-spp frame sequence with pixel history linear models (seed 003) and the
// baselines of its Table 2 (TAA after Karis 2014, FXAA after Lottes 2011) plus the exponential history of its
// eq. 1. The methods and their parameters come from the library's registry (temporal/phlm/filters.h); the
// sequence runner owns the frame loop. Options, defaults and every choice: docs/filter-phlm.md.
#include "tool.h"

#include "temporal/phlm/filters.h"

#include <string>

namespace {

using namespace temporal;

std::string description() {
  std::string methods;
  for (const auto& m : filter_methods()) methods += std::string("  ") + m.name + ": " + m.summary + "\n";
  return "Temporal filtering of a 1-spp sequence: pixel history linear models (seed 003, --method phlm), the "
         "engine-strength baseline taa, and the papers' weak references ema and fxaa.\n" +
         methods +
         "State per pixel (persistent, kept across frames; --state-out writes it):\n"
         "  phlm, 3 channels: " +
         std::to_string(phlm_state_floats(3) * 4) + " bytes (beta 3x4 = 12, P 4x4 as UD factors = 10, feature 3, "
         "scale 1 floats)\n"
         "  phlm, 1 channel (--layer ssao): " +
         std::to_string(phlm_state_floats(1) * 4) +
         " bytes (beta 1x2, P 2x2 as UD factors = 3, feature 1, scale 1 floats)\n"
         "  taa: 12 bytes (RGB history); ema: 12 bytes + 8 with a G-buffer (previous depth and id); fxaa: none\n"
         "Double buffering (read the previous models at p + motion, write the new ones) holds twice that in memory.";
}

}  // namespace

int main(int argc, char** argv) {
  tool::Tool tool("filter-phlm", description());
  SequenceOptions seq;
  FilterOptions options;
  auto& app = tool.app();
  tool.add_sequence_options(
      seq, {"Input sequence, e.g. color.####.exr (1 spp, scene-linear)",
            "G-buffer sequence with `motion` (and `depth` for taa's nearest-depth velocity, `depth`, `id` for ema); "
            "without it the scene is static",
            "Output sequence, e.g. phlm.####.exr", false, true, true});
  app.add_option("--method", options.method, filter_method_names());
  app.add_option("--layer", options.layer, "Layer to filter: rgb (R,G,B) or a layer name (ssao, shadow, direct, ...)");
  app.add_flag("--debug-layers", options.debug_layers, "Add debug.* layers (phlm: feature, alpha, reset, traceP; taa: clip, noHistory, velocity; ema: reject; "
                 "fxaa: edge)");
  for (const auto& method : filter_methods()) tool.add_params(method.params(options), method.name);
  return tool.run(argc, argv, [&]() -> Status {
    auto stage = make_filter_stage(options);
    if (!stage) return stage.error();
    auto summary = run_sequence(seq, **stage, tool.identity(), tool.hooks());
    if (!summary) return summary.error();
    if (summary->non_finite_input > 0)
      tool.log("pixels with NaN or Inf in total: " + std::to_string(summary->non_finite_input));
    return Status::ok();
  });
}
