// The methods of filter-phlm (temporal/phlm/filters.h): one line each.
#include "temporal/phlm/filters.h"

namespace temporal {
namespace {

ParamList phlm_params(FilterOptions& o) {
  PhlmParams& p = o.phlm;
  return {
      Param::real("--lambda", "phlm: RLS forgetting factor (seed 003 eq. 6-7)", &p.lambda, 0.5, 1.0),
      Param::positive("--p-init", "phlm: P = p_init * I at reset (seed 003 section 6)", &p.p_init),
      Param::real("--feature-a", "phlm: a of phi(v,l) = a l^2 + b v l^3 (section 5.1)", &p.feature_a, -1e6, 1e6),
      Param::real("--feature-b", "phlm: b of phi(v,l)", &p.feature_b, -1e6, 1e6),
      Param::positive("--trace-factor", "phlm: trace(P) <= factor * N * p_init (wind-up guard)", &p.trace_factor),
      Param::flag_on("--no-feature",
                     "phlm ablation: predictor x = [1], an intercept-only RLS (a per-pixel running mean with the same "
                     "resets)",
                     &p.no_feature),
      Param::flag_on("--no-box-test", "phlm ablation: skip the box test and its resets (Algorithm 1 lines 13-19)",
                     &p.no_box_test),
      Param::choice("--feature-alpha",
                    "phlm: reading of the feature's alpha: ue4 = weight of the new sample, eq1 = history weight of "
                    "eq. 1 (ablation)",
                    &p.alpha_reading, {"ue4", "eq1"}),
      Param::choice("--model-fetch", "phlm: fetch of the previous models at p + motion (section 6: bilinear)",
                    &p.model_fetch, {"bilinear", "nearest", "catmull-rom"}),
  };
}
ParamList taa_params(FilterOptions& o) {
  TaaParams& p = o.taa;
  return {
      Param::real("--taa-alpha", "taa: weight of the current frame (chosen on the tuning set, docs/filter-phlm.md)",
                  &p.alpha, 0.0, 1.0),
      Param::choice("--taa-velocity",
                    "taa: motion of the closest surface of the 3x3 neighbourhood (nearest, UE4) or of the pixel",
                    &p.velocity, {"nearest", "centre"}),
      Param::choice("--taa-clip",
                    "taa: history clipping in YCoCg to mu +- gamma sigma (variance, Salvi 2016) or to the 3x3 "
                    "min/max box (minmax, Karis 2014)",
                    &p.clip, {"variance", "minmax"}),
      Param::positive("--taa-gamma", "taa: gamma of variance clipping (Salvi 2016: 1)", &p.gamma, 0.0, 8.0),
      Param::choice("--taa-history", "taa: history fetch (Karis 2014: catmull-rom)", &p.history,
                    {"catmull-rom", "bilinear", "nearest"}),
  };
}
ParamList ema_params(FilterOptions& o) {
  return {
      Param::real("--ema-alpha", "ema: history weight alpha of seed 003 eq. 1", &o.ema.alpha, 0.0, 1.0),
      Param::positive("--ema-depth-tolerance",
                      "ema: relative depth difference of the disocclusion test (temporal/core/reproject.h)",
                      &o.ema.depth_tolerance),
      Param::positive("--ema-warped-depth-tolerance",
                      "ema: the same when the G-buffer has prevDepth.Z (the warped depth, temporal/core/reproject.h)",
                      &o.ema.warped_depth_tolerance),
  };
}
ParamList fxaa_params(FilterOptions& o) {
  FxaaParams& p = o.fxaa;
  return {
      Param::real("--fxaa-subpix", "fxaa: sub-pixel aliasing removal (fxaaQualitySubpix)", &p.subpix, 0.0, 1.0),
      Param::real("--fxaa-edge-threshold", "fxaa: fxaaQualityEdgeThreshold", &p.edge_threshold, 0.0, 1.0),
      Param::real("--fxaa-edge-threshold-min", "fxaa: fxaaQualityEdgeThresholdMin", &p.edge_threshold_min, 0.0, 1.0),
  };
}

template <typename Filter, typename Params>
std::unique_ptr<FrameFilter> make(const Params& p) {
  return std::make_unique<Filter>(p);
}

const LayerNeed kMotion{"motion"};

}  // namespace

const std::vector<FilterMethod>& filter_methods() {
  static const std::vector<FilterMethod> methods = {
      {"phlm", "pixel history linear models (seed 003)", {kMotion}, phlm_params,
       [](const FilterOptions& o) { return make<PhlmFilter>(o.phlm); }},
      {"taa",
       "engine-strength TAA: Karis 2014 with nearest-depth velocity, Catmull-Rom history, variance clipping "
       "(Salvi 2016)",
       {kMotion, {"depth", false}}, taa_params,
       [](const FilterOptions& o) { return make<TaaFilter>(o.taa); }},
      {"ema", "weak reference: the exponential history of seed 003 eq. 1, disocclusion by depth and id", {kMotion, {"depth"}, {"id"}, {"prevDepth", false}},
       ema_params, [](const FilterOptions& o) { return make<EmaFilter>(o.ema); }},
      {"fxaa", "weak reference: FXAA 3.11 (Lottes 2011), spatial only", {}, fxaa_params,
       [](const FilterOptions& o) { return make<FxaaFilter>(o.fxaa); }},
  };
  return methods;
}

const FilterMethod* find_filter_method(std::string_view name) {
  for (const auto& m : filter_methods())
    if (name == m.name) return &m;
  return nullptr;
}

std::string filter_method_names() {
  std::string s;
  for (const auto& m : filter_methods()) {
    if (!s.empty()) s += " | ";
    s += m.name;
  }
  return s;
}

}  // namespace temporal
