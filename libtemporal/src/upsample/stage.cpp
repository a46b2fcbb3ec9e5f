// The upsampling stage under the sequence runner (temporal/upsample/stage.h).
#include "temporal/upsample/stage.h"

#include "method.h"
#include "temporal/gpu/device.h"

#include <cstdio>
#include <sstream>

namespace temporal::upsample {
namespace {

std::vector<std::string> split_layers(const std::string& layer) {
  std::vector<std::string> out;
  std::stringstream in(layer.empty() ? std::string("rgb") : layer);
  std::string item;
  while (std::getline(in, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

}  // namespace

UpsampleStage::UpsampleStage(Options options) : upsampler_(std::move(options)) {
  const Options& o = upsampler_.options();
  inputs_.input_layers = split_layers(o.layer);
  if (const MethodEntry* e = find_entry(o.method)) inputs_.gbuffer_layers = e->layers(o);
  if (o.demodulate) inputs_.gbuffer_layers.push_back({"albedo", true, "needed by --demodulate"});
  inputs_.gbuffer_required = true;
  inputs_.gbuffer_purpose = "the geometry of the joint-bilateral weights and the motion of the history fetch";
  inputs_.gbuffer_scale = 0;  // k from the input's temporal:jitterFactor
}

Status UpsampleStage::load_state(const Image& state, const std::string& source) {
  if (Status s = upsampler_.load_state(state, source); !s) return s;
  resume_after_ = state.metadata().frame;
  return Status::ok();
}

Status UpsampleStage::process(const StageFrame& frame, std::vector<StageOutput>& out) {
  const Options& o = upsampler_.options();
  if (resume_after_ && frame.index == 0 && frame.frame != *resume_after_ + 1)
    return Error::usage("the state of --state-in was written after frame " + std::to_string(*resume_after_) +
                        ", but this run starts at frame " + std::to_string(frame.frame) + ": resume with --frames " +
                        std::to_string(*resume_after_ + 1) + "-..., or drop --state-in");
  resume_after_.reset();
  auto channels = select_channels(*frame.input, o.layer, frame.input_path);
  if (!channels) return channels.error();
  auto result = upsampler_.process(*frame.gbuffer, *frame.input, *channels, frame.cut, &last_,
                                   {frame.gbuffer_path, frame.input_path});
  if (!result) return result.error();
  Image& img = **result;
  // The G-buffer's header (camera, clip planes, frame, time) without the input's jitter.
  FrameMetadata md = frame.gbuffer->metadata();
  md.jitter.reset();
  md.jitter_factor.reset();
  md.jitter_index.reset();
  md.camera_cut = last_.history_reset;
  img.metadata() = md;
  StageOutput output;
  output.frame = frame.frame;
  output.image = &img;
  output.keep_input_metadata = false;
  output.timings_ms = frame.input->metadata().timings_ms;
  output.timings_ms["upsample"] = last_.wall_ms;  // on the GPU with the uploads and downloads
  gpu::record_device(output, upsampler_.gpu_context(), {last_.compute_ms, last_.compute_clock});
  const MethodEntry* entry = find_entry(o.method);
  output.extra["method"] = entry && entry->header_name ? entry->header_name(o) : o.method;
  if (const std::string p = method_parameters(o); !p.empty()) output.extra["methodParameters"] = p;
  output.extra["holePixels"] = std::to_string(last_.hole_pixels);
  output.extra["historyPixels"] = std::to_string(last_.history_pixels);
  output.extra["nonFiniteInput"] = std::to_string(last_.non_finite_input);
  out.push_back(std::move(output));
  totals_.non_finite_input += last_.non_finite_input;
  totals_.hole_pixels += last_.hole_pixels;
  totals_.history_pixels += last_.history_pixels;
  totals_.compute_ms += last_.compute_ms;
  return Status::ok();
}

std::string UpsampleStage::frame_summary() const {
  char line[160];
  std::snprintf(line, sizeof line, "%.2f ms, %zu pixels without history, %zu non-finite inputs", last_.compute_ms,
                last_.hole_pixels, last_.non_finite_input);
  return line;
}

}  // namespace temporal::upsample
