// The render-gbuffer sequence loop (replay.h).
#include "temporal/render/replay.h"

#include <cmath>

#include <glm/matrix.hpp>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>

namespace temporal {

Expected<ExrCompression> parse_replay_compression(const std::string& name) {
  auto c = parse_compression(name);
  if (!c) return c.error();
  if (*c == ExrCompression::Dwaa) return Error::usage("--compression dwaa is lossy on data layers: use zip, piz or none");
  return *c;
}

const char* compression_name(ExrCompression compression) {
  switch (compression) {
    case ExrCompression::None: return "none";
    case ExrCompression::Piz: return "piz";
    case ExrCompression::Dwaa: return "dwaa";
    case ExrCompression::Zip: break;
  }
  return "zip";
}

Status validate(const ReplayOptions& options) {
  if (!(options.fps > 0.0)) return Error::usage("--fps must be positive");
  if (options.compression == ExrCompression::Dwaa)
    return Error::usage("--compression dwaa is lossy on data layers: use zip, piz or none");
  if (options.frames && options.frames->first < 0) return Error::usage("--frames must not be negative");
  if (options.frames && options.duration_s > 0.0) return Error::usage("give --frames or --duration, not both");
  if (!(options.fps <= 10000.0)) return Error::usage("--fps must be at most 10000");
  // Bounded so that a typing error (inf, 1e30) cannot start a render of 2^31 frames: at most a million frames.
  if (!(options.duration_s >= 0.0) || !(options.duration_s * options.fps <= 1e6))
    return Error::usage("--duration must be between 0 and 1e6 / fps seconds (a million frames); got " +
                        std::to_string(options.duration_s));
  if (options.frames && options.frames->count() > 1'000'000)
    return Error::usage("--frames covers more than a million frames: render it in parts");
  return {};
}

FrameRange replay_frames(const Scene& scene, const ReplayOptions& options) {
  return options.frames ? *options.frames : scene.default_frames(options.fps, options.duration_s);
}

namespace {

// A camera whose transform is singular (a node scaled by 0) or not finite has no view: every pixel would be NaN.
Status check_camera(const FrameState& state, int frame, double fps) {
  const glm::mat4& v = state.camera.view;
  const CameraState& cam = state.camera;
  bool finite = std::isfinite(cam.yfov) && std::isfinite(cam.znear) && std::isfinite(cam.zfar) && cam.yfov > 0.0f &&
                cam.znear > 0.0f && cam.zfar > cam.znear;
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) finite = finite && std::isfinite(v[c][r]);
  const float det = glm::determinant(glm::mat3(v));
  if (finite && std::abs(det) > 1e-12f) return {};
  return Error::input({}, "the camera's transform at frame " + std::to_string(frame) + " (t = " + std::to_string(frame / fps) +
                              " s) is " + (finite ? "singular (a camera node scaled by 0?)" : "not finite") +
                              ": fix the scene's camera, or pass --camera-path orbit|dolly for an automatic one");
}

std::string frame_path(const std::string& dir, const char* name, int frame) {
  return (std::filesystem::path(dir) / (std::string(name) + "." + frame_digits(frame) + ".exr")).string();
}

const char* const kPasses[] = {kPassGbuffer, kPassLightMaps, kPassShadeLow, kPassShadeFull, kPassReference, kPassColor};

// timings.csv: one row per frame, the time of each pass in ms (empty when it did not run).
class TimingsCsv {
 public:
  explicit TimingsCsv(std::string path) : path_(std::move(path)), out_(path_) {}
  Status header() {
    if (!out_) return Error::output(path_, "cannot write (check permissions)");
    out_ << "frame,time";
    for (const char* p : kPasses) out_ << ',' << p;
    out_ << '\n';
    return {};
  }
  Status row(int frame, double time, const std::map<std::string, double>& ms) {
    out_ << frame << ',' << std::setprecision(9) << time;
    for (const char* p : kPasses) {
      out_ << ',';
      if (auto it = ms.find(p); it != ms.end()) out_ << std::fixed << std::setprecision(3) << it->second << std::defaultfloat;
    }
    out_ << '\n' << std::flush;
    if (!out_) return Error::output(path_, "write failed (disk full?)");
    return {};
  }

 private:
  std::string path_;
  std::ofstream out_;
};

Status write_outputs(RenderedFrame& rendered, const ReplayOptions& options, int frame) {
  ExrWriteOptions wo;
  wo.compression = options.compression;
  const std::pair<const char*, std::optional<Image>*> images[] = {
      {"gbuffer", &rendered.gbuffer}, {"shade", &rendered.shade}, {"reference", &rendered.reference}, {"color", &rendered.color}};
  for (auto& [name, image] : images) {
    if (!*image) continue;
    (*image)->metadata().tool = options.tool;
    (*image)->metadata().parameters = options.parameters;
    if (auto s = write_exr(frame_path(options.out_dir, name, frame), **image, wo); !s) return s;
  }
  return {};
}

}  // namespace

Status replay(const Scene& scene, const RenderOptions& render, const ReplayOptions& options, const ReplayHooks& hooks) {
  if (auto s = validate(options); !s) return s;
  if (auto s = validate(render); !s) return s;
  const FrameRange range = replay_frames(scene, options);
  auto renderer = Renderer::create(render, geometry_of(scene));
  if (!renderer) return renderer.error();
  auto log = [&](const std::string& line) {
    if (hooks.log) hooks.log(line);
  };
  log("OpenGL: " + renderer->gl_description());
  log("frames " + std::to_string(range.first) + "-" + std::to_string(range.last) + " at " + std::to_string(options.fps) + " fps");

  std::error_code ec;
  std::filesystem::create_directories(options.out_dir, ec);
  if (ec || !std::filesystem::is_directory(options.out_dir))
    return Error::output(options.out_dir, "cannot create the output folder: " + ec.message());
  TimingsCsv csv((std::filesystem::path(options.out_dir) / "timings.csv").string());
  if (auto s = csv.header(); !s) return s;

  std::optional<FrameState> previous;
  if (range.first > 0) previous = scene.evaluate(double(range.first - 1) / options.fps);
  for (int frame = range.first; frame <= range.last; ++frame) {
    FrameState current = scene.evaluate(double(frame) / options.fps);
    FrameInput in;
    in.frame = frame;
    in.fps = options.fps;
    in.current = &current;
    in.previous = previous ? &*previous : nullptr;
    // Only frame 0 starts the sequence: a render of frames A-B (a shard of a longer sequence, docs/pipelines.md)
    // evaluates frame A - 1 for its motion and gives exactly the files of a single run over 0-B, headers included.
    in.camera_cut = frame == 0;
    if (Status s = check_camera(current, frame, options.fps); !s) return s;
    auto rendered = renderer->render(in);
    if (!rendered) return rendered.error();
    if (auto s = write_outputs(*rendered, options, frame); !s) return s;
    if (auto s = csv.row(frame, double(frame) / options.fps, rendered->timings_ms); !s) return s;
    if (hooks.frame_done) hooks.frame_done(frame, frame - range.first + 1, range.count());
    previous = std::move(current);
  }
  return {};
}

}  // namespace temporal
