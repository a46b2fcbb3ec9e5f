// The sequence runner (temporal/io/runner.h).
#include "temporal/io/runner.h"

#include <sys/stat.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <deque>
#include <filesystem>

namespace temporal {
namespace {

std::string dims(int w, int h) { return std::to_string(w) + "x" + std::to_string(h); }

// Outputs are OpenEXR: refuse another extension before any work is done.
Status check_output_name(const std::string& pattern, const char* option) {
  std::string ext = std::filesystem::path(pattern).extension().string();
  for (auto& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".exr") return Status::ok();
  return Error::usage(std::string(option) + " '" + pattern + "' must end in .exr: the tools write OpenEXR");
}

// Everything the loop needs, resolved from the options once.
struct Plan {
  SequencePattern input, out;
  std::optional<SequencePattern> gbuffer, state_out;
  std::vector<int> frames;
  std::set<int> resets;
  ExrWriteOptions write;
};

Expected<Plan> make_plan(const SequenceOptions& o, const StageInputs& needs) {
  auto input = SequencePattern::parse(o.input);
  if (!input) return input.error();
  auto out = SequencePattern::parse(o.out);
  if (!out) return out.error();
  if ((input->has_placeholder() || needs.outputs_per_frame > 1) && !out->has_placeholder())
    return Error::usage("--out '" + o.out + "' needs a frame placeholder (#### or %04d) for a sequence");
  if (Status s = check_output_name(o.out, "--out"); !s) return s.error();
  if (!o.state_out.empty())
    if (Status s = check_output_name(o.state_out, "--state-out"); !s) return s.error();
  OutputPaths outputs;
  if (Status s = outputs.add(o.out, "--out"); !s) return s.error();
  if (!o.state_out.empty())
    if (Status s = outputs.add(o.state_out, "--state-out"); !s) return s.error();
  std::optional<FrameRange> range;
  if (!o.frames.empty()) {
    auto r = FrameRange::parse(o.frames);
    if (!r) return r.error();
    range = *r;
  }
  auto frames = resolve_frames(*input, range);
  if (!frames) return frames.error();
  // One file in (no placeholder) and no --frames: the run's frame is the file's own (its temporal:frame), not 0.
  // Frame 0 wrote `a.0000.exr` stamped `temporal:frame 0` beside frame 3's `temporal:time` (issue 25). A file
  // without that attribute is frame 0, except into a frame pattern, where the number would be a guess.
  if (!input->has_placeholder() && !range) {
    auto info = read_exr_info(o.input);
    if (!info) return info.error();
    if (info->metadata.frame)
      frames = std::vector<int>{*info->metadata.frame};
    else if (out->has_placeholder())
      return Error::usage("--input '" + o.input + "' is one file without a temporal:frame attribute, so --out '" + o.out +
                          "' has no frame number to take: give --frames N (the frame it is) or an --out without ####");
  }
  auto compression = parse_data_compression(o.compression);
  if (!compression) return compression.error();
  Plan plan{*input, *out, std::nullopt, std::nullopt, *frames, {}, {}};
  plan.write.compression = *compression;
  if (!o.reset_frames.empty()) {
    auto list = parse_frame_list(o.reset_frames);
    if (!list) return list.error();
    plan.resets.insert(list->begin(), list->end());
  }
  if (o.gbuffer.empty()) {
    if (needs.gbuffer_required)
      return Error::usage("this method needs --gbuffer G.####.exr (" + needs.gbuffer_purpose + ")");
  } else if (!needs.gbuffer_layers.empty()) {
    auto g = SequencePattern::parse(o.gbuffer);
    if (!g) return g.error();
    // Every G-buffer file of the range must exist before any work is done.
    for (int f : plan.frames) {
      auto found = input_exists(g->path(f));
      if (!found) return found.error();
      if (!*found)
        return Error::input(g->path(f), "missing: the G-buffer of frame " + std::to_string(f) + " (--gbuffer) does not "
                                        "exist; render it or narrow --frames");
    }
    plan.gbuffer = *g;
  }
  if (!o.state_out.empty()) {
    auto s = SequencePattern::parse(o.state_out);
    if (!s) return s.error();
    plan.state_out = *s;
  }
  return plan;
}

// The G-buffer layers to read (selection for read_exr): the required ones, and each optional one that the first
// G-buffer file has (e.g. prevDepth: read when present, absent otherwise; a sequence has the same layers throughout).
std::vector<std::string> gbuffer_selection(const StageInputs& needs, const std::string& first_gbuffer) {
  std::optional<std::vector<std::string>> have;
  std::vector<std::string> layers;
  for (const auto& n : needs.gbuffer_layers) {
    if (!n.required) {
      if (!have) {
        auto info = read_exr_info(first_gbuffer);
        have = info ? info->channels : std::vector<std::string>{};
      }
      auto channels = layer_channel_names(n.layer);
      bool present = false;
      for (const auto& c : *have)
        present = present || (channels.empty() ? c.rfind(n.layer + ".", 0) == 0
                                               : std::find(channels.begin(), channels.end(), c) != channels.end());
      if (!present) continue;
    }
    layers.push_back(n.layer);
  }
  return layers;
}

// The required G-buffer layers that the first G-buffer file lacks, said for a G-buffer: read_exr's message
// ("no layer 'depth, N, motion, id' ... or pick another --layer") pointed a colour file given as --gbuffer at
// --layer, which does not choose G-buffer layers (issue 25).
Status check_gbuffer_file(const StageInputs& needs, const std::string& path) {
  auto info = read_exr_info(path);
  if (!info) return info.error();
  std::string missing, alternatives;
  for (const auto& n : needs.gbuffer_layers) {
    if (!n.required) continue;
    const auto channels = layer_channel_names(n.layer);
    bool present = false;
    for (const auto& c : info->channels)
      present = present || (channels.empty() ? c.rfind(n.layer + ".", 0) == 0
                                             : std::find(channels.begin(), channels.end(), c) != channels.end());
    if (present) continue;
    missing += (missing.empty() ? "" : ", ") + n.layer;
    if (!n.alternative.empty()) alternatives += " (" + n.layer + ": " + n.alternative + ")";
  }
  if (missing.empty()) return Status::ok();
  bool colour = !info->channels.empty();
  std::string have;
  for (const auto& c : info->channels) {
    colour = colour && (c == "R" || c == "G" || c == "B" || c == "A" || c.find('.') != std::string::npos) &&
             c.rfind("motion.", 0) != 0 && c.rfind("depth.", 0) != 0 && c.rfind("N.", 0) != 0 && c != "id";
    if (have.size() < 120) have += (have.empty() ? "" : ", ") + c;
  }
  return Error::input(path, "--gbuffer: this file has no " + missing + " layer (it has " + have + ")" +
                                (colour ? ": it looks like a colour image. --gbuffer takes the G-buffer, e.g. "
                                          "gbuffer.####.exr from render-gbuffer --outputs gbuffer"
                                        : "; render the G-buffer with render-gbuffer --outputs gbuffer") +
                                alternatives);
}

// Reads frames in order, keeping the lookahead frames in memory (each file is read once).
class InputWindow {
 public:
  InputWindow(const Plan& plan, const StageInputs& needs) : plan_(plan), needs_(needs) {}
  // The current frame followed by up to `lookahead` next frames that exist on disk.
  Status advance(int frame) {
    while (!cache_.empty() && cache_.front().first < frame) cache_.pop_front();
    int next = cache_.empty() ? frame : cache_.back().first + 1;
    const int last = needs_.lookahead_past_range ? frame + needs_.lookahead
                                                 : std::min(frame + needs_.lookahead, plan_.frames.back());
    for (; next <= last; ++next) {
      const std::string path = plan_.input.path(next);
      std::error_code ec;  // a lookahead frame that cannot be examined (a link loop) is read below and reported
      if (next != frame && !std::filesystem::exists(path, ec) && !ec) break;
      auto img = read_exr(path, ExrSelection{needs_.input_layers});
      if (!img) {
        Error e = img.error();
        if (e.file.empty()) e.file = path;
        return e;
      }
      cache_.emplace_back(next, std::move(*img));
    }
    return Status::ok();
  }
  const Image& current() const { return cache_.front().second; }
  std::vector<const Image*> next() const {
    std::vector<const Image*> v;
    for (std::size_t i = 1; i < cache_.size(); ++i) v.push_back(&cache_[i].second);
    return v;
  }

 private:
  const Plan& plan_;
  const StageInputs& needs_;
  std::deque<std::pair<int, Image>> cache_;
};

// The size the G-buffer must have for this input frame.
Status check_gbuffer_size(const Image& g, const Image& input, const StageInputs& needs, const std::string& gpath,
                          const std::string& ipath) {
  int k = needs.gbuffer_scale;
  if (k == 0 && !input.metadata().jitter_factor)
    return Error::input(ipath, "no temporal:jitterFactor in the header: the G-buffer's size is k times this input's, "
                               "with k from that attribute (render-gbuffer --outputs shade writes it; "
                               "docs/conventions.md, Jitter)");
  if (k == 0) k = *input.metadata().jitter_factor;
  if (g.width() == k * input.width() && g.height() == k * input.height()) return Status::ok();
  if (k == 1)
    return Error::input(gpath, "G-buffer is " + dims(g.width(), g.height()) + " but " + ipath + " is " +
                                   dims(input.width(), input.height()) + "; render both at the same --size");
  return Error::input(ipath, "size mismatch: G-buffer " + dims(g.width(), g.height()) + " (" + gpath + ") must be k = " +
                                 std::to_string(k) + " times the input " + dims(input.width(), input.height()) +
                                 " per axis (full = k * low)");
}

Status write_state(const Plan& plan, const FrameStage& stage, const RunIdentity& id, int frame, const ProtectedInputs& inputs) {
  if (Status s = inputs.check(plan.state_out->path(frame), "--state-out"); !s) return s;
  auto state = stage.save_state();
  if (!state) return state.error();
  FrameMetadata& md = state->metadata();
  md.frame = frame;
  md.tool = id.tool;
  md.parameters = id.parameters;
  return write_exr(plan.state_out->path(frame), *state, plan.write);
}

}  // namespace

void ProtectedInputs::add(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0) ids_.insert({std::uint64_t(st.st_dev), std::uint64_t(st.st_ino)});
}

namespace {

// Does file name `name` match the frame pattern prefix + digits + suffix?
bool matches_pattern(const std::string& name, const std::string& prefix, const std::string& suffix) {
  if (name.size() <= prefix.size() + suffix.size() || name.compare(0, prefix.size(), prefix) != 0 ||
      name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0)
    return false;
  const std::string digits = name.substr(prefix.size(), name.size() - prefix.size() - suffix.size());
  return digits.find_first_not_of("0123456789") == std::string::npos;
}

}  // namespace

Status OutputPaths::add(const std::string& path, const std::string& what) {
  namespace fs = std::filesystem;
  auto pattern = SequencePattern::parse(path);
  if (!pattern) return pattern.error();
  std::error_code ec;
  if (!pattern->has_placeholder()) {
    const fs::file_status st = fs::status(path, ec);
    if (!ec && fs::exists(st) && !fs::is_regular_file(st))
      return Error::usage(what + " '" + path + "' exists and is not a regular file (" +
                          (fs::is_directory(st) ? "a folder" : "a device, pipe or socket") +
                          "): name a new file or a regular one to replace");
  }
  Entry e;
  const fs::path p(pattern->has_placeholder() ? pattern->prefix() : path);
  const fs::path folder = p.has_parent_path() ? p.parent_path() : fs::path(".");
  e.folder = fs::weakly_canonical(fs::absolute(folder, ec), ec).string();
  e.pattern = pattern->has_placeholder();
  e.prefix = p.filename().string();
  e.suffix = e.pattern ? pattern->suffix() : std::string();
  e.what = what;
  e.text = path;
  for (const Entry& o : entries_) {
    if (o.folder != e.folder) continue;
    bool same = false;
    if (e.pattern && o.pattern)
      same = e.prefix == o.prefix && e.suffix == o.suffix;  // any width: "####" and "%d" share frames >= 1000
    else if (e.pattern)
      same = matches_pattern(o.prefix, e.prefix, e.suffix);
    else if (o.pattern)
      same = matches_pattern(e.prefix, o.prefix, o.suffix);
    else
      same = e.prefix == o.prefix;
    if (same)
      return Error::usage(what + " '" + path + "' names the same file" + (e.pattern || o.pattern ? "s" : "") + " as " +
                          o.what + " '" + o.text + "': one would overwrite the other; give each output its own name");
  }
  entries_.push_back(std::move(e));
  return Status::ok();
}

Status ProtectedInputs::check(const std::string& path, const std::string& what) const {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0 || !ids_.count({std::uint64_t(st.st_dev), std::uint64_t(st.st_ino)}))
    return Status::ok();
  return Error::usage(what + " '" + path + "' is one of this run's inputs: writing it would destroy data not read "
                      "yet; choose another output folder or name");
}

Expected<ExrCompression> parse_data_compression(const std::string& name) {
  auto c = parse_compression(name);
  if (!c) return c.error();
  if (*c == ExrCompression::Dwaa)
    return Error::usage("--compression dwaa is lossy (it compresses `*.Y` data as luminance): use none, zip or piz");
  return *c;
}

namespace {

// Every file the run reads: no output may replace one of them (an output pattern equal to an input pattern,
// another spelling of it, or a link to it).
Expected<ProtectedInputs> run_inputs(const SequenceOptions& options, const Plan& plan, const StageInputs& needs) {
  ProtectedInputs inputs;
  for (const int f : plan.frames) {
    inputs.add(plan.input.path(f));
    for (int k = 1; k <= needs.lookahead; ++k) inputs.add(plan.input.path(f + k));
    if (plan.gbuffer) inputs.add(plan.gbuffer->path(f));
  }
  if (!options.state_in.empty()) inputs.add(options.state_in);
  for (const std::string& other : options.other_inputs) {
    auto p = SequencePattern::parse(other);
    if (!p) return p.error();
    for (int f : plan.frames) inputs.add(p->path(f));
  }
  return inputs;
}

// Stamps the stage's outputs of one input frame (the run's identity, the frame, the method's timings) and writes
// them under the output pattern.
Status write_outputs(const Plan& plan, const RunIdentity& identity, const ProtectedInputs& inputs,
                     const Image& input, std::vector<StageOutput>& outputs, RunSummary& summary) {
  for (auto& o : outputs) {
    FrameMetadata md = o.keep_input_metadata ? input.metadata() : o.image->metadata();
    md.frame = o.frame;
    md.tool = identity.tool;
    md.parameters = identity.parameters;
    md.compute_ms = o.compute_ms;
    md.timings_ms = o.timings_ms;  // the input's pass timings describe another stage
    for (const auto& k : o.drop_extra) md.extra.erase(k);
    for (const auto& [k, v] : o.extra) md.extra[k] = v;
    o.image->metadata() = std::move(md);
    const std::string path = plan.out.path(o.frame);
    if (Status s = inputs.check(path, "--out"); !s) return s;
    if (Status s = write_exr(path, *o.image, plan.write); !s) return s;
    summary.compute_ms += o.compute_ms;
    ++summary.outputs;
  }
  return Status::ok();
}

}  // namespace

Expected<RunSummary> run_sequence(const SequenceOptions& options, FrameStage& stage, const RunIdentity& identity,
                                  const RunHooks& hooks) {
  const StageInputs& needs = stage.inputs();
  auto plan = make_plan(options, needs);
  if (!plan) return plan.error();
  if ((!options.state_in.empty() || !options.state_out.empty()) && !stage.has_state())
    return Error::usage("this method has no state: drop --state-in / --state-out");
  auto warn = [&](const std::string& file, const std::string& text) {
    if (hooks.warning) hooks.warning(file, text);
  };
  auto log = [&](const std::string& text) {
    if (hooks.log) hooks.log(text);
  };
  // A method that reads motion, run over several frames without a G-buffer, takes every pixel as still: on a
  // moving scene its history ghosts (issue 25: taa lost 1.7 dB and said nothing). Say so once, before the work.
  if (!plan->gbuffer && plan->frames.size() > 1)
    for (const LayerNeed& n : needs.gbuffer_layers)
      if (n.layer == "motion") {
        warn(options.input, "no --gbuffer: this method reads motion vectors, so without them every pixel is taken "
                            "as still (a static scene) and moving content smears; give --gbuffer G.####.exr "
                            "(render-gbuffer --outputs gbuffer writes it)");
        break;
      }
  bool resumed = false;
  if (!options.state_in.empty()) {
    auto state = read_exr(options.state_in);
    if (!state) return state.error();
    if (Status s = stage.load_state(*state, options.state_in); !s) {
      Error e = s.error();
      if (e.file.empty()) e.file = options.state_in;
      return e;
    }
    resumed = true;
  }

  auto protected_inputs = run_inputs(options, *plan, needs);
  if (!protected_inputs) return protected_inputs.error();
  ProtectedInputs& inputs = *protected_inputs;
  if (Status s = inputs.check(plan->out.path(plan->frames.front()), "--out"); !s) return s.error();
  if (plan->state_out)
    if (Status s = inputs.check(plan->state_out->path(plan->frames.front()), "--state-out"); !s) return s.error();

  if (plan->gbuffer)
    if (Status s = check_gbuffer_file(needs, plan->gbuffer->path(plan->frames.front())); !s) return s.error();

  RunSummary summary;
  InputWindow window(*plan, needs);
  int width = 0, height = 0;
  const std::vector<std::string> gsel =
      plan->gbuffer ? gbuffer_selection(needs, plan->gbuffer->path(plan->frames.front())) : std::vector<std::string>{};
  std::vector<StageOutput> outputs;
  int prev = -1;
  const std::size_t n = plan->frames.size();
  for (std::size_t i = 0; i < n; ++i) {
    const int frame = plan->frames[i];
    StageFrame sf;
    sf.frame = frame;
    sf.index = i;
    sf.count = n;
    sf.input_path = plan->input.path(frame);
    if (Status s = window.advance(frame); !s) return s.error();
    sf.input = &window.current();
    sf.next = window.next();
    if (i == 0) {
      width = sf.input->width();
      height = sf.input->height();
    } else if (sf.input->width() != width || sf.input->height() != height) {
      return Error::input(sf.input_path, "is " + dims(sf.input->width(), sf.input->height()) + " but frame " +
                                             std::to_string(plan->frames.front()) + " is " + dims(width, height) +
                                             ": every frame of a sequence must have one size");
    }
    if (const std::size_t bad = count_non_finite_layers(*sf.input, needs.input_layers, kMaxSampleMagnitude); bad > 0) {
      warn(sf.input_path, std::to_string(bad) +
                              " pixels hold NaN, Inf or a magnitude above 1e10: treated as missing samples and kept out "
                              "of every history");
      summary.non_finite_input += bad;
    }
    Image gbuffer;
    if (plan->gbuffer) {
      sf.gbuffer_path = plan->gbuffer->path(frame);
      auto g = read_exr(sf.gbuffer_path, ExrSelection{gsel});
      if (!g) return g.error();
      if (Status s = check_gbuffer_layers(*g, needs.gbuffer_layers, sf.gbuffer_path); !s) return s.error();
      if (Status s = check_gbuffer_size(*g, *sf.input, needs, sf.gbuffer_path, sf.input_path); !s) return s.error();
      if (const std::size_t bad = count_non_finite_layers(*g, gsel); bad > 0) {
        warn(sf.gbuffer_path, std::to_string(bad) + " pixels hold NaN or Inf in the G-buffer: they get no history "
                                                     "and no spatial weight");
        summary.non_finite_gbuffer += bad;
      }
      gbuffer = std::move(*g);
      sf.gbuffer = &gbuffer;
    }
    sf.cut = (i == 0 && !resumed) || plan->resets.count(frame) > 0 || (prev >= 0 && frame != prev + 1) ||
             sf.input->metadata().camera_cut.value_or(false) ||
             (sf.gbuffer && i > 0 && sf.gbuffer->metadata().camera_cut.value_or(false));
    outputs.clear();
    if (Status s = stage.process(sf, outputs); !s) {
      Error e = s.error();
      if (e.file.empty()) e.file = sf.input_path;
      return e;
    }
    if (Status s = write_outputs(*plan, identity, inputs, *sf.input, outputs, summary); !s) return s.error();
    if (plan->state_out && (plan->state_out->has_placeholder() || i + 1 == n))
      if (Status s = write_state(*plan, stage, identity, frame, inputs); !s) return s.error();
    if (const std::string line = stage.frame_summary(); !line.empty())
      log("frame " + std::to_string(frame) + ": " + line + (sf.cut ? " (history reset)" : ""));
    if (hooks.frame_done) hooks.frame_done(frame, int(i + 1), int(n));
    prev = frame;
    ++summary.frames;
  }
  return summary;
}

}  // namespace temporal
