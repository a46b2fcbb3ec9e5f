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
  };
}
ParamList taa_params(FilterOptions& o) {
  return {Param::real("--taa-alpha", "taa: weight of the current frame", &o.taa.alpha, 0.0, 1.0)};
}
ParamList ema_params(FilterOptions& o) {
  return {
      Param::real("--ema-alpha", "ema: history weight alpha of seed 003 eq. 1", &o.ema.alpha, 0.0, 1.0),
      Param::positive("--ema-depth-tolerance",
                      "ema: relative depth difference of the disocclusion test (temporal/core/reproject.h)",
                      &o.ema.depth_tolerance),
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
      {"taa", "temporal antialiasing after Karis 2014 (seed 003 Table 2's baseline)", {kMotion}, taa_params,
       [](const FilterOptions& o) { return make<TaaFilter>(o.taa); }},
      {"ema", "exponential history of seed 003 eq. 1, disocclusion by depth and id", {kMotion, {"depth"}, {"id"}},
       ema_params, [](const FilterOptions& o) { return make<EmaFilter>(o.ema); }},
      {"fxaa", "FXAA 3.11 (Lottes 2011), spatial", {}, fxaa_params,
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
