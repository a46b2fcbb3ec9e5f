// morph-120hz: turns a rendered sequence (e.g. 40 Hz) into a display-rate sequence (e.g. 120 Hz) with seed
// 004's grid morphing (didyk) or a baseline; or, with --perceive, simulates what an eye tracking the motion
// perceives on a hold-type display (seed 004 section 3). The methods, their parameters and the per-frame policy
// live in libtemporal (temporal/morph/methods.h, morph_stage.h); docs/morph-120hz.md describes them.
#include "method_list.h"
#include "tool.h"

#include "temporal/io/color_config.h"
#include "temporal/io/exr.h"
#include "temporal/morph/methods.h"
#include "temporal/morph/morph_stage.h"

#include <algorithm>
#include <string>

int main(int argc, char** argv) {
  using namespace temporal;
  using namespace temporal::morph;
  std::string methods;
  for (const MethodEntry* e : registry()) methods += "\n  " + e->info.name + ": " + e->info.summary;
  tool::Tool tool("morph-120hz",
                  "Temporal upsampling of rendered frames for high-refresh-rate displays (Didyk et al. 2010): "
                  "each input frame n becomes output frames n*factor+k, k = 0..factor-1, at time "
                  "(n*factor+k)/(fps*factor). With --perceive: simulate hold-type blur under smooth pursuit.\n"
                  "Methods:" + methods);
  CLI::App& app = tool.app();
  SequenceOptions seq;
  tool::Tool::SequenceFlags flags;
  flags.input_help = "Colour sequence (R,G,B scene-linear), e.g. render/color.####.exr";
  flags.gbuffer_help = "G-buffer sequence with motion and depth (the methods that read it, and --perceive)";
  flags.out_help = "Output sequence pattern, e.g. out/color.####.exr";
  flags.reset_frames = false;  // no method keeps a history
  tool.add_sequence_options(seq, flags);
  MorphStageOptions options;
  tool.add_params(morph_stage_params(options));
  app.get_option("--display")->excludes("--gamma");
  for (const char* geometry : {"--screen-width-m", "--distance-m", "--pixels-x"})
    app.get_option(geometry)->excludes("--ppd");
  // --list-methods(-json), for scripts (pipelines/morph-120hz.sh) and the workflow: the registry's methods.
  tool::add_method_lists(tool, tool::method_rows(registry()));

  return tool.run(argc, argv, [&]() -> Status {
    auto stage = make_morph_stage(options, MorphStageIO{&read_exr_rgb, &load_display_gamma});
    if (!stage) return stage.error();
    if (!options.lag_reference.empty()) seq.other_inputs.push_back(options.lag_reference);  // never an output
    auto summary = run_sequence(seq, **stage, tool.identity(), tool.hooks());
    if (!summary) return summary.error();
    tool.log(std::to_string(summary->frames) + " input frames, " + std::to_string(summary->outputs) +
             " output frames, " + std::to_string(summary->compute_ms / double(std::max<std::size_t>(summary->outputs, 1))) +
             " ms compute per output frame");
    return Status::ok();
  });
}
