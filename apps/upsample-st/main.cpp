// upsample-st: rebuilds the full-resolution shading payload from 1/k-resolution jittered shading and the
// full-resolution G-buffer, with the methods of seed 000 (spatial, temporal, herzog) and seed 002 (drobot).
// The algorithms, the per-frame loop and the method table live in libtemporal (temporal/upsample/stage.h,
// temporal/upsample/methods.h); docs/upsample-st.md describes them.
#include "method_list.h"
#include "tool.h"

#include "temporal/upsample/methods.h"
#include "temporal/upsample/stage.h"

#include <cstdio>
#include <string>
#include <vector>

namespace {

using namespace temporal;
namespace up = temporal::upsample;

std::string description() {
  std::string d =
      "Upsamples low-resolution jittered shading (the shade sequence of render-gbuffer) to the resolution of the "
      "G-buffer. Methods:\n";
  for (const up::MethodEntry* e : up::registry()) d += "  " + e->info.name + ": " + e->info.summary + "\n";
  return d + "Typical use: upsample-st --gbuffer G.####.exr --input shade.####.exr --out up.####.exr --method herzog";
}

}  // namespace

int main(int argc, char** argv) {
  tool::Tool tool("upsample-st", description());
  SequenceOptions sequence;
  tool.add_sequence_options(
      sequence, {"Low-resolution shading sequence (1/k per axis; jitter and k from its metadata), e.g. shade.####.exr",
                 "Full-resolution G-buffer sequence (depth, N, motion, id; only the layers the method needs are read)",
                 "Output sequence, e.g. up.####.exr", true, true, true});
  up::Options options;
  tool.add_params(up::params(options));
  // --list-methods(-json): every method and named variant, then the name suffixes any method takes ("-demod");
  // pipelines/upsample-st.sh turns METHODS names into arguments with it.
  std::vector<tool::SuffixRow> suffixes;
  for (const up::VariantSuffix& s : up::variant_suffixes()) suffixes.push_back({s.suffix, s.args, s.summary});
  tool::add_method_lists(tool, tool::method_rows(up::registry()), suffixes);

  return tool.run(argc, argv, [&]() -> Status {
    if (Status s = up::check(options); !s) return s;
    up::UpsampleStage stage(options);
    auto summary = run_sequence(sequence, stage, tool.identity(), tool.hooks());
    if (!summary) return summary.error();
    const up::FrameStats& t = stage.totals();
    char line[200];
    std::snprintf(line, sizeof line,
                  "%zu frames, %.2f ms per frame (upsampling only), %zu pixels without history, %zu non-finite inputs",
                  summary->frames, summary->frames ? t.compute_ms / double(summary->frames) : 0.0, t.hole_pixels,
                  t.non_finite_input);
    tool.log(line);
    return Status::ok();
  });
}
