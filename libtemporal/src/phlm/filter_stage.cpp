// filter-phlm's stage of the sequence runner (temporal/phlm/filters.h): the layer's channels, the G-buffer planes
// the method reads, timing, and the state files.
#include "temporal/phlm/filters.h"

#include "temporal/gpu/device.h"

#include <chrono>

namespace temporal::phlm {
namespace {

std::string dims(int w, int h) { return std::to_string(w) + "x" + std::to_string(h); }

// Channels of the filtered layer (select_layers, the --layer rule of every tool); 1 or 3 of them.
Expected<std::vector<std::string>> layer_channels(const Image& img, const std::string& layer, const std::string& file) {
  auto selected = select_layers(img, layer, file);
  if (!selected) return selected.error();
  const std::vector<std::string>& names = *selected;
  if (names.size() != 1 && names.size() != 3)
    return Error::usage("--layer " + layer + " has " + std::to_string(names.size()) +
                        " channels; the filters take 1 (e.g. ssao) or 3 (rgb, direct)");
  return names;
}

class FilterStage final : public FrameStage {
 public:
  FilterStage(const FilterOptions& options, const MethodEntry& method, std::shared_ptr<gpu::Context> context,
              std::unique_ptr<FrameFilter> filter)
      : options_(options), method_(method), context_(std::move(context)), filter_(std::move(filter)) {
    inputs_.input_layers = layer_items(options.layer);
    inputs_.gbuffer_layers = method.layers(options);
    // Every parameter of the method with its value (ablation switches included), for the output headers.
    FilterOptions copy = options;
    if (MethodOptions* m = copy.per_method.find(method.info.name))
      for (const Param& p : m->params()) {
        if (!parameters_.empty()) parameters_ += ' ';
        parameters_ += p.flag + "=" + param_value_text(p);
      }
  }
  const StageInputs& inputs() const override { return inputs_; }
  bool has_state() const override { return method_.info.has_state; }

  Expected<Image> save_state() const override {
    Image state = filter_->saved_state();
    state.metadata().extra["phlmStateOf"] = method_.info.name;
    return state;
  }
  // The channel count is known at the first frame: the state is applied there.
  Status load_state(const Image& state, const std::string& source) override {
    auto of = state.metadata().extra.find("phlmStateOf");
    if (of != state.metadata().extra.end() && of->second != method_.info.name)
      return Error::usage("the state was written by --method " + of->second + ", not " + method_.info.name +
                          ": resume with the same method");
    pending_state_ = state;
    pending_source_ = source;
    return Status::ok();
  }

  Status process(const StageFrame& f, std::vector<StageOutput>& out) override {
    auto channels = layer_channels(*f.input, options_.layer, f.input_path);
    if (!channels) return channels.error();
    if (pending_state_) {
      const Image& state = *pending_state_;
      if (state.width() != f.input->width() || state.height() != f.input->height())
        return Error::input(f.input_path, "the --state-in state is " + dims(state.width(), state.height()) +
                                              " but the input is " + dims(f.input->width(), f.input->height()));
      if (Status s = filter_->set_state(state, int(channels->size())); !s) {
        Error e = s.error();
        if (e.file.empty()) e.file = pending_source_;  // the state's error, not the input's
        return e;
      }
      pending_state_.reset();
    }
    FilterInput in;
    in.color = f.input;
    in.channels = *channels;
    in.debug = options_.debug_layers;
    in.jitter = f.input->metadata().jitter.value_or(glm::vec2(0.0f));
    in.reset = f.cut;
    if (f.gbuffer) {
      in.motion_x = f.gbuffer->plane("motion.X");
      in.motion_y = f.gbuffer->plane("motion.Y");
      in.depth = f.gbuffer->plane("depth.Z");
      in.id = f.gbuffer->uint_plane("id");
      in.prev_depth = f.gbuffer->plane("prevDepth.Z");  // read only by the methods that list it (ema)
    }
    const auto t0 = std::chrono::steady_clock::now();
    stats_ = {};
    if (Status s = filter_->process(in, output_, &stats_); !s) return s;
    const double wall_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    // On the GPU the kernels' time (gpu/device.h); `temporal:ms:filter` keeps the call's wall-clock time, with the
    // uploads and downloads.
    const gpu::ComputeTime time =
        gpu::compute_time(context_ ? dynamic_cast<const gpu::TimedKernel*>(filter_.get()) : nullptr, wall_ms);
    ms_ = time.ms;
    StageOutput o;
    o.frame = f.frame;
    o.image = &output_;
    o.timings_ms = {{"filter", wall_ms}};
    o.extra = {{"method", method_.info.name}, {"methodParameters", parameters_}};
    gpu::record_device(o, context_.get(), time);
    out.push_back(std::move(o));
    return Status::ok();
  }

  std::string frame_summary() const override {
    return std::to_string(ms_) + " ms, resets " + std::to_string(stats_.history_resets) + ", box " +
           std::to_string(stats_.clamped) + filter_->stats_text(stats_);
  }

 private:
  FilterOptions options_;
  const MethodEntry& method_;
  std::shared_ptr<gpu::Context> context_;  // --device gpu: the filter's context; null on the CPU
  std::unique_ptr<FrameFilter> filter_;
  StageInputs inputs_;
  std::optional<Image> pending_state_;
  std::string pending_source_;  // the --state-in file, for the errors set_state finds
  std::string parameters_;  // "--lambda=0.998 --p-init=1000 ..." (temporal:methodParameters)
  Image output_;
  FilterStats stats_;
  double ms_ = 0.0;
};

}  // namespace

Expected<std::unique_ptr<FrameStage>> make_filter_stage(const FilterOptions& options) {
  if (Status s = check(options); !s) return s.error();
  auto context = gpu::context_for_device(options.device);  // null on the CPU
  if (!context) return context.error();
  auto filter = make_filter(options, *context);
  if (!filter) return filter.error();
  return std::unique_ptr<FrameStage>(
      std::make_unique<FilterStage>(options, *find_entry(options.method), *context, std::move(*filter)));
}

}  // namespace temporal::phlm
