// compare's metric registry (temporal/compare/comparison.h): the table every output iterates. A new metric is
// its source file (defining `MetricDefinition <name>_metric()`, see registry.h) and one line in kMetrics below;
// the order is the order of the CSV columns of the later metrics, the JSON keys, the charts, the summary table
// and `compare --list-metrics`.
#include "registry.h"

#include <nlohmann/json.hpp>

// X(name): the metric `name`, defined by name##_metric() in its metric_*.cpp. Each line both declares that
// function and registers it, so a new metric is one line here.
#define TEMPORAL_METRICS(X)                   \
  X(psnr_rgb)     /* metric_psnr.cpp */         \
  X(psnr_y)       /* metric_psnr.cpp */         \
  X(ssim)         /* metric_ssim.cpp */         \
  X(flicker)      /* metric_flicker.cpp */      \
  X(flip)         /* metric_flip.cpp */         \
  X(psnr_latency) /* metric_psnr_latency.cpp */ \
  /* a new metric: one line above this one */

namespace temporal {

#define TEMPORAL_DECLARE_METRIC(name) MetricDefinition name##_metric();
TEMPORAL_METRICS(TEMPORAL_DECLARE_METRIC)
#undef TEMPORAL_DECLARE_METRIC

const std::vector<MetricDefinition>& metric_registry() {
  static const std::vector<MetricDefinition> registry = [] {
    std::vector<MetricDefinition> r;
#define TEMPORAL_REGISTER_METRIC(name) r.push_back(name##_metric());
    TEMPORAL_METRICS(TEMPORAL_REGISTER_METRIC)
#undef TEMPORAL_REGISTER_METRIC
    return r;
  }();
  return registry;
}

const MetricDefinition* find_metric(std::string_view name) {
  for (const auto& d : metric_registry())
    if (d.name == name) return &d;
  return nullptr;
}

std::vector<const MetricDefinition*> enabled_metrics(const ComparisonSetup& setup) {
  std::vector<const MetricDefinition*> out;
  for (const auto& d : metric_registry())
    if (!d.enabled || d.enabled(setup)) out.push_back(&d);
  return out;
}

std::string unit_suffix(const MetricDefinition& metric) { return metric.unit.empty() ? std::string() : " " + metric.unit; }

std::string metric_list_text() {
  std::string out;
  for (const auto& d : metric_registry())
    out += d.name + "\t" + d.label + "\t" + d.unit + "\t" + (d.higher_is_better ? "higher" : "lower") + "\n";
  return out;
}

std::string metric_list_json() {
  using json = nlohmann::ordered_json;
  json list = json::array();
  for (const auto& d : metric_registry()) {
    json columns = json::array();
    for (const auto& c : d.columns) columns.push_back(c.csv);
    auto bound = [](const std::optional<double>& v) { return v ? json(*v) : json(nullptr); };
    list.push_back({{"name", d.name},
                    {"label", d.label},
                    {"unit", d.unit},
                    {"better", d.higher_is_better ? "higher" : "lower"},
                    {"columns", columns},
                    {"threshold_option", d.threshold_option.empty() ? json(nullptr) : json("--fail-" + d.threshold_option)},
                    {"always_measured", d.enabled == nullptr},
                    {"enable_hint", d.enable_hint},
                    {"lowest", bound(d.chart.lowest)},
                    {"highest", bound(d.chart.highest)}});
  }
  return list.dump(2) + "\n";
}

}  // namespace temporal
