// upsample-st: rebuilds the full-resolution shading payload from 1/k-resolution jittered shading and the
// full-resolution G-buffer, with the methods of seed 000 (spatial, temporal, herzog) and seed 002 (drobot).
// The algorithms, the per-frame loop and the method table live in libtemporal (temporal/upsample/stage.h,
// temporal/upsample/methods.h); docs/upsample-st.md describes them.
#include "tool.h"

#include "temporal/upsample/methods.h"
#include "temporal/upsample/stage.h"

#include <cstdio>
#include <iostream>
#include <string>

namespace {

using namespace temporal;
namespace up = temporal::upsample;

std::string join_args(const std::vector<std::string>& args) {
  std::string s;
  for (const auto& a : args) s += " " + a;
  return s;
}

// --list-methods: one line per method and named variant, tab-separated (name, arguments, summary), then the name
// suffixes any method takes; pipelines/upsample-st.sh turns METHODS names into arguments with it.
void list_methods() {
  for (const up::MethodVariant& v : up::method_variants())
    std::cout << v.name << "\t--method " << v.method << join_args(v.args) << "\t" << v.summary << "\n";
  for (const up::VariantSuffix& s : up::variant_suffixes())
    std::cout << "*" << s.suffix << "\t" << join_args(s.args).substr(1) << "\t" << s.summary << "\n";
}

std::string description() {
  std::string d =
      "Upsamples low-resolution jittered shading (the shade sequence of render-gbuffer) to the resolution of the "
      "G-buffer. Methods:\n";
  for (const up::MethodInfo& m : up::methods()) d += "  " + m.name + ": " + m.summary + "\n";
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
  tool.app().add_flag_callback(
      "--list-methods",
      [] {
        list_methods();
        throw CLI::Success();
      },
      "List the methods and their named variants (name, arguments, summary) and exit");

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
