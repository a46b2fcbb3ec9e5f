// compare's metric registry (temporal/compare/comparison.h): the table every output iterates. A new metric is
// its source file (declared in registry.h) and one line here; the order is the order of the CSV columns of the
// later metrics, the JSON keys, the charts and the summary table.
#include "registry.h"

namespace temporal {

const std::vector<MetricDefinition>& metric_registry() {
  static const std::vector<MetricDefinition> registry = [] {
    std::vector<MetricDefinition> r;
    r.push_back(psnr_rgb_metric());
    r.push_back(psnr_y_metric());
    r.push_back(ssim_metric());
    r.push_back(flicker_metric());
    r.push_back(flip_metric());
    r.push_back(psnr_latency_metric());
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

}  // namespace temporal
