// --list-methods and --list-methods-json of the method tools (upsample-st, filter-phlm, morph-120hz), printed the
// same way from each stage's registry (temporal/core/method.h). The text form is for people and shell scripts:
// one tab-separated line per method and named variant (name, the arguments that select it, summary, the devices
// of its implementations: `cpu` or `cpu,gpu`, what --device takes), then the name suffixes any method takes
// ("*-demod", its arguments, summary). The JSON form is for the pipelines: an array with one object per method and
// named variant,
//   {"name": "herzog-lagged", "method": "herzog", "args": ["--lagged-wf"], "summary": "...", "stateful": true,
//    "implementations": ["cpu", "gpu"], "latency_frames": 1}
// ("latency_frames" only where the stage has the notion: morph-120hz, in rendered frames), followed by one object
// per name suffix, {"suffix": "-demod", "args": ["--demodulate"], "summary": "..."} (objects without "method").
#pragma once

#include "temporal/core/method.h"
#include "tool.h"

#include <optional>
#include <string>
#include <vector>

namespace temporal::tool {

// One method with its defaults, or one of its named variants.
struct MethodRow {
  MethodVariant variant;  // name, method, args, summary
  bool stateful = false;
  std::vector<std::string> implementations;  // devices: {"cpu"}, {"cpu", "gpu"}
  std::optional<int> latency_frames;
};

// A name suffix any method takes (upsample-st's "-demod").
struct SuffixRow {
  std::string suffix;
  std::vector<std::string> args;
  std::string summary;
};

// The rows of a stage's registry, in its order: each method, then its named variants.
template <typename Entry>
std::vector<MethodRow> method_rows(const std::vector<const Entry*>& registry) {
  std::vector<MethodRow> rows;
  for (const Entry* e : registry) {
    MethodRow base{{e->info.name, e->info.name, {}, e->info.summary}, e->info.has_state,
                   implementation_devices(*e), e->info.latency_frames};
    rows.push_back(base);
    for (const MethodVariant& v : e->info.variants) {
      MethodRow row = base;
      row.variant = v;
      rows.push_back(std::move(row));
    }
  }
  return rows;
}

std::string method_list_text(const std::vector<MethodRow>& rows, const std::vector<SuffixRow>& suffixes = {});
std::string method_list_json(const std::vector<MethodRow>& rows, const std::vector<SuffixRow>& suffixes = {});

// Adds --list-methods and --list-methods-json to `tool`: each prints its form to stdout and exits 0.
void add_method_lists(Tool& tool, std::vector<MethodRow> rows, std::vector<SuffixRow> suffixes = {});

}  // namespace temporal::tool
