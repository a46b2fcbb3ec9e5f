// The render-gbuffer sequence loop (replay.h).
#include "temporal/replay/replay.h"

#include "temporal/io/atomic_file.h"

#include <glm/matrix.hpp>

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <map>
#include <sstream>

namespace temporal {

namespace fs = std::filesystem;

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
// An animated field of view (USD focalLength) below kMinCameraYfov projects everything to NaN: refused too.
Status check_camera(const std::string& file, const FrameState& state, int frame, double fps) {
  const glm::mat4& v = state.camera.view;
  const CameraState& cam = state.camera;
  bool finite = std::isfinite(cam.yfov) && std::isfinite(cam.znear) && std::isfinite(cam.zfar) &&
                cam.yfov >= kMinCameraYfov && cam.yfov < 3.1416f && cam.znear > 0.0f && cam.zfar > cam.znear &&
                std::isfinite(cam.aspect) && cam.aspect >= 0.0f;
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) finite = finite && std::isfinite(v[c][r]);
  const float det = glm::determinant(glm::mat3(v));
  if (finite && std::abs(det) > 1e-12f) return {};
  return Error::input(file, "the camera's transform or projection" +
                               (cam.name.empty() ? std::string() : " (camera '" + cam.name + "')") + " at frame " + std::to_string(frame) + " (t = " + std::to_string(frame / fps) +
                              " s) is " + (finite ? "singular (a camera node scaled by 0?)" : "not finite (or a field of view under 1e-4 rad)") +
                              ": fix the scene's camera, or pass --camera-path orbit|dolly for an automatic one");
}

std::string frame_path(const std::string& dir, const char* name, int frame) {
  return (std::filesystem::path(dir) / (std::string(name) + "." + frame_digits(frame) + ".exr")).string();
}

const char* const kPasses[] = {kPassGbuffer, kPassLightMaps, kPassShadeLow, kPassShadeFull, kPassReference, kPassColor};

// timings.csv: one row per frame, the time of each pass in ms (empty when it did not run). Shards of one sequence
// (render-gbuffer runs with the same --out and different --frames, as pipelines/Snakefile's render_chunk starts
// them, possibly at the same time) share the file: each frame's row is merged into it - other frames' rows kept,
// this frame's replaced, sorted by frame - under an exclusive flock on DIR/.timings.csv.lock, and the file is
// replaced atomically, so that neither a concurrent shard nor an interrupted run loses a row (docs/render-gbuffer.md).
class TimingsCsv {
 public:
  explicit TimingsCsv(std::string path)
      : path_(std::move(path)),
        lock_path_((std::filesystem::path(path_).parent_path() / ".timings.csv.lock").string()) {
    header_ = "frame,time";
    for (const char* p : kPasses) header_ += std::string(",") + p;
  }

  // Before any frame is rendered: an existing file must be a timings file of this layout (its rows are kept).
  Status check() {
    Lock lock;
    if (auto s = lock.acquire(lock_path_); !s) return s;
    std::map<int, std::string> rows;
    return read(rows);
  }

  Status row(int frame, double time, const std::map<std::string, double>& ms) {
    std::ostringstream line;
    line << frame << ',' << std::setprecision(9) << time;
    for (const char* p : kPasses) {
      line << ',';
      if (auto it = ms.find(p); it != ms.end()) line << std::fixed << std::setprecision(3) << it->second << std::defaultfloat;
    }
    Lock lock;
    if (auto s = lock.acquire(lock_path_); !s) return s;
    std::map<int, std::string> rows;
    if (auto s = read(rows); !s) return s;
    rows[frame] = line.str();
    std::string text = header_ + '\n';
    for (const auto& [f, r] : rows) text += r + '\n';
    return write_text_atomic(path_, text);
  }

 private:
  // An exclusive flock on the lock file, released when destroyed (or when the process ends, however it ends).
  class Lock {
   public:
    Lock() = default;
    Lock(const Lock&) = delete;
    Lock& operator=(const Lock&) = delete;
    ~Lock() {
      if (fd_ >= 0) ::close(fd_);  // closing releases the lock
    }
    Status acquire(const std::string& path) {
      fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
      if (fd_ < 0) return Error::output(path, std::string("cannot open the lock file of timings.csv: ") + std::strerror(errno));
      int rc = 0;
      while ((rc = ::flock(fd_, LOCK_EX)) != 0 && errno == EINTR) {
      }
      if (rc != 0)
        return Error::output(path, std::string("cannot lock (needed so that shards writing into one folder keep each "
                                               "other's timings; does this filesystem support flock?): ") +
                                       std::strerror(errno));
      return {};
    }

   private:
    int fd_ = -1;
  };

  // The rows of the existing file by frame (none when it does not exist).
  Status read(std::map<int, std::string>& rows) const {
    std::error_code ec;
    if (!std::filesystem::exists(path_, ec) && !ec) return {};
    std::ifstream in(path_);
    if (!in) return Error::output(path_, "cannot read the existing timings (to keep its rows): " + ec.message());
    std::string line;
    if (!std::getline(in, line) || line != header_)
      return Error::output(path_, "exists but is not a timings file of this render-gbuffer (its first line is not '" +
                                      header_ + "'): move it away or choose another --out");
    while (std::getline(in, line)) {
      if (line.empty()) continue;
      int frame = 0;
      const auto comma = line.find(',');
      const auto [end, err] = std::from_chars(line.data(), line.data() + std::min(comma, line.size()), frame);
      if (err != std::errc() || end != line.data() + comma)
        return Error::output(path_, "has a row that does not start with a frame number ('" + line.substr(0, 40) +
                                        "'): move it away or choose another --out");
      rows[frame] = line;
    }
    return {};
  }

  std::string path_, lock_path_, header_;
};

// render-gbuffer writes into a folder that may hold its own inputs (a scene named timings.csv, a USD texture named
// color.0000.exr): every output of the run is checked, by file identity (links and other spellings included),
// against every file the scene load read, and the run is refused before anything is rendered (Usage error).
Status check_outputs_against_inputs(const Scene& scene, const RenderOptions& render, const ReplayOptions& options,
                                    const FrameRange& range) {
  std::map<std::pair<std::uint64_t, std::uint64_t>, std::string> inputs;
  for (const std::string& file : scene.input_files()) {
    struct stat st {};
    if (::stat(file.c_str(), &st) == 0) inputs.emplace(std::pair{std::uint64_t(st.st_dev), std::uint64_t(st.st_ino)}, file);
  }
  auto check = [&](const std::string& output) -> Status {
    struct stat st {};
    if (::stat(output.c_str(), &st) != 0) return {};
    auto it = inputs.find({std::uint64_t(st.st_dev), std::uint64_t(st.st_ino)});
    if (it == inputs.end()) return {};
    return Error::usage("the output '" + output + "' is the scene's input '" + it->second +
                        "': writing it would destroy it; choose another --out folder");
  };
  const fs::path dir(options.out_dir);
  if (auto s = check((dir / "timings.csv").string()); !s) return s;
  if (auto s = check((dir / ".timings.csv.lock").string()); !s) return s;
  const std::pair<const char*, bool> outputs[] = {{"gbuffer", render.outputs.gbuffer},
                                                  {"shade", render.outputs.shade},
                                                  {"reference", render.outputs.reference},
                                                  {"color", render.outputs.color}};
  // Only files that exist can be inputs: the folder is scanned instead of stat-ing every frame of a long range.
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    for (const auto& [output, on] : outputs) {
      if (!on) continue;
      const std::string prefix = std::string(output) + ".";
      if (name.rfind(prefix, 0) != 0) continue;
      int frame = 0;
      const char* digits = name.data() + prefix.size();
      const auto [end_digits, err] = std::from_chars(digits, name.data() + name.size(), frame);
      if (err != std::errc() || frame < range.first || frame > range.last) continue;
      if (it->path().string() != frame_path(options.out_dir, output, frame)) continue;
      if (auto s = check(it->path().string()); !s) return s;
    }
  }
  return {};
}

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
  if (ec || !std::filesystem::is_directory(options.out_dir, ec))
    return Error::output(options.out_dir, "cannot create the output folder: " + ec.message());
  if (auto s = check_outputs_against_inputs(scene, render, options, range); !s) return s;
  TimingsCsv csv((std::filesystem::path(options.out_dir) / "timings.csv").string());
  if (auto s = csv.check(); !s) return s;

  std::optional<FrameState> previous;
  if (range.first > 0) previous = scene.evaluate(double(range.first - 1) / options.fps);
  int previous_frame = range.first - 1;
  for (int frame : range.frames()) {
    // A stepped list (--frames 0-47x3) skips frames: the motion of frame N is always from the scene at N - 1.
    if (frame != previous_frame + 1 && frame > 0) previous = scene.evaluate(double(frame - 1) / options.fps);
    previous_frame = frame;
    FrameState current = scene.evaluate(double(frame) / options.fps);
    FrameInput in;
    in.frame = frame;
    in.fps = options.fps;
    in.current = &current;
    in.previous = previous ? &*previous : nullptr;
    // Only frame 0 starts the sequence: a render of frames A-B (a shard of a longer sequence, docs/pipelines.md)
    // evaluates frame A - 1 for its motion and gives exactly the files of a single run over 0-B, headers included.
    in.camera_cut = frame == 0;
    if (Status s = check_camera(scene.file(), current, frame, options.fps); !s) return s;
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
