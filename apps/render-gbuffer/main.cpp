// render-gbuffer: replays an animated glTF scene with OSMesa into multi-layer EXR sequences
// (docs/render-gbuffer.md). Parses options, evaluates the scene per frame, renders and writes; the
// rendering lives in libtemporal (temporal/render/render.h), the scene in temporal/scene/scene.h.
#include "tool.h"

#include "temporal/core/exr.h"
#include "temporal/render/render.h"
#include "temporal/scene/scene.h"
#include "temporal/core/sequence.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <optional>
#include <sstream>

using namespace temporal;

namespace {

struct Options {
  std::string scene;
  std::string out;
  std::string size = "1280x1024";
  double fps = 40.0;
  std::string frames;
  double duration = 0.0;
  std::string camera;
  std::string clip;
  std::string camera_path = "fixed";
  double camera_period = 8.0;
  std::string payload = "direct,shadow,ssao,gi";
  int factor = 4;
  std::string jitter = "random";
  std::string shade_jitter = "regular";
  int reference_spp = 16;
  std::string outputs = "gbuffer,shade,reference,color";
  int pcf = 6;
  int shadow_map_size = 2048;
  float shadow_bias = 1.5f;
  int ssao_directions = 8;
  int ssao_steps = 8;
  float ssao_radius = 0.0f;
  int vpls = 2000;
  int rsm_size = 128;
  bool no_mipmaps = false;
  std::string shade_mip_bias = "auto";
  std::uint32_t seed = 0;
  std::string compression = "zip";
};

Expected<std::pair<int, int>> parse_size(const std::string& s) {
  int w = 0, h = 0;
  char x = 0, extra = 0;
  std::istringstream in(s);
  if (!(in >> w >> x >> h) || (x != 'x' && x != 'X') || (in >> extra) || w < 1 || h < 1)
    return Error::usage("--size '" + s + "' is not WIDTHxHEIGHT (e.g. 1280x1024)");
  return std::pair{w, h};
}

std::string frame_path(const std::string& dir, const char* name, int frame) {
  char buf[32];
  std::snprintf(buf, sizeof buf, ".%04d.exr", frame);
  return (std::filesystem::path(dir) / (std::string(name) + buf)).string();
}

Status run(const tool::Tool& tool, const Options& opt) {
  // Options first: a bad value is a usage error before any work.
  auto size = parse_size(opt.size);
  if (!size) return size.error();
  if (!(opt.fps > 0.0)) return Error::usage("--fps must be positive");
  auto payload = parse_payload_terms(opt.payload);
  if (!payload) return payload.error();
  auto outputs = RenderOutputs::parse(opt.outputs);
  if (!outputs) return outputs.error();
  auto color_jitter = parse_jitter_mode(opt.jitter);
  if (!color_jitter) return color_jitter.error();
  auto shade_jitter = parse_jitter_mode(opt.shade_jitter);
  if (!shade_jitter) return shade_jitter.error();
  auto compression = parse_compression(opt.compression);
  if (!compression) return compression.error();
  if (*compression == ExrCompression::Dwaa) return Error::usage("--compression dwaa is lossy on data layers: use zip, piz or none");

  RenderOptions ro;
  ro.width = size->first;
  ro.height = size->second;
  ro.factor = opt.factor;
  ro.shade_jitter = *shade_jitter;
  ro.color_jitter = *color_jitter;
  ro.reference_spp = opt.reference_spp;
  ro.mipmaps = !opt.no_mipmaps;
  if (opt.shade_mip_bias != "auto") {
    float bias = 0.0f;
    char extra = 0;
    std::istringstream in(opt.shade_mip_bias);
    if (!(in >> bias) || (in >> extra))
      return Error::usage("--shade-mip-bias '" + opt.shade_mip_bias + "' is not a number or 'auto'");
    ro.shade_mip_bias = bias;
  }
  ro.seed = opt.seed;
  ro.outputs = *outputs;
  ro.payload = *payload;
  ro.payload.pcf_kernel = opt.pcf;
  ro.payload.shadow_map_size = opt.shadow_map_size;
  ro.payload.shadow_bias = opt.shadow_bias;
  ro.payload.ssao_directions = opt.ssao_directions;
  ro.payload.ssao_steps = opt.ssao_steps;
  ro.payload.ssao_radius = opt.ssao_radius;
  ro.payload.vpl_count = opt.vpls;
  ro.payload.rsm_size = opt.rsm_size;
  if (auto s = validate(ro); !s) return s;

  SceneLoadOptions load;
  load.clip = opt.clip;
  load.camera.camera = opt.camera;
  load.camera.path_period_s = opt.camera_period;
  if (opt.camera_path == "fixed") load.camera.path = CameraOptions::Path::Fixed;
  else if (opt.camera_path == "orbit") load.camera.path = CameraOptions::Path::Orbit;
  else if (opt.camera_path == "dolly") load.camera.path = CameraOptions::Path::Dolly;
  else return Error::usage("--camera-path '" + opt.camera_path + "': use fixed, orbit or dolly");

  auto scene = Scene::load(opt.scene, load);
  if (!scene) return scene.error();

  // Frames: --frames A-B, or --duration S (frames 0 .. ceil(S * fps) - 1), or the clip's length, or one
  // camera-path period, or a single frame of a static scene.
  int first = 0, last = 0;
  if (!opt.frames.empty()) {
    auto range = FrameRange::parse(opt.frames);
    if (!range) return range.error();
    if (range->first < 0) return Error::usage("--frames must not be negative");
    first = range->first;
    last = range->last;
  } else {
    double seconds = opt.duration;
    if (seconds <= 0.0) seconds = scene->clip_duration();
    if (seconds <= 0.0 && load.camera.path != CameraOptions::Path::Fixed) seconds = opt.camera_period;
    last = seconds > 0.0 ? std::max(0, int(std::ceil(seconds * opt.fps - 1e-9)) - 1) : 0;
  }

  // llvmpipe reads LP_NUM_THREADS when the context is created.
  if (tool.threads() > 0) setenv("LP_NUM_THREADS", std::to_string(tool.threads()).c_str(), 1);

  SceneGeometry geometry;
  geometry.primitives = &scene->primitives();
  geometry.materials = &scene->materials();
  geometry.textures = &scene->textures();
  geometry.bounds_min = scene->bounds_min();
  geometry.bounds_max = scene->bounds_max();
  auto renderer = Renderer::create(ro, geometry);
  if (!renderer) return renderer.error();
  tool.log("OpenGL: " + renderer->gl_description());
  tool.log("frames " + std::to_string(first) + "-" + std::to_string(last) + " at " + std::to_string(opt.fps) + " fps");

  std::error_code ec;
  std::filesystem::create_directories(opt.out, ec);
  if (ec || !std::filesystem::is_directory(opt.out))
    return Error::output(opt.out, "cannot create the output folder: " + ec.message());
  const std::string csv_path = (std::filesystem::path(opt.out) / "timings.csv").string();
  std::ofstream csv(csv_path);
  if (!csv) return Error::output(csv_path, "cannot write (check permissions)");
  const char* passes[] = {kPassGbuffer, kPassLightMaps, kPassShadeLow, kPassShadeFull, kPassReference, kPassColor};
  csv << "frame,time";
  for (const char* p : passes) csv << ',' << p;
  csv << '\n';

  ExrWriteOptions wo;
  wo.compression = *compression;
  tool::Progress progress(tool.name(), last - first + 1);
  std::optional<FrameState> previous;
  if (first > 0) previous = scene->evaluate(double(first - 1) / opt.fps);
  for (int frame = first; frame <= last; ++frame) {
    FrameState current = scene->evaluate(double(frame) / opt.fps);
    FrameInput in;
    in.frame = frame;
    in.fps = opt.fps;
    in.current = &current;
    in.previous = previous ? &*previous : nullptr;
    in.camera_cut = frame == first;
    auto rendered = renderer->render(in);
    if (!rendered) return rendered.error();
    const std::pair<const char*, std::optional<Image>*> images[] = {
        {"gbuffer", &rendered->gbuffer}, {"shade", &rendered->shade}, {"reference", &rendered->reference},
        {"color", &rendered->color}};
    for (auto& [name, image] : images) {
      if (!*image) continue;
      (*image)->metadata().tool = tool.signature();
      (*image)->metadata().parameters = tool.command_line();
      if (auto s = write_exr(frame_path(opt.out, name, frame), **image, wo); !s) return s;
    }
    csv << frame << ',' << std::setprecision(9) << double(frame) / opt.fps;
    for (const char* p : passes) {
      csv << ',';
      if (auto it = rendered->timings_ms.find(p); it != rendered->timings_ms.end())
        csv << std::fixed << std::setprecision(3) << it->second << std::defaultfloat;
    }
    csv << '\n' << std::flush;
    if (!csv) return Error::output(csv_path, "write failed (disk full?)");
    progress.step(frame);
    previous = std::move(current);
  }
  return {};
}

}  // namespace

int main(int argc, char** argv) {
  tool::Tool tool("render-gbuffer",
                  "Replays an animated glTF 2.0 scene with OSMesa (llvmpipe) into multi-layer EXR sequences:\n"
                  "G-buffer, low-resolution jittered payload, supersampled reference and 1-spp colour.");
  Options opt;
  auto& app = tool.app();
  app.add_option("scene", opt.scene, "glTF 2.0 scene (.gltf or .glb)")->required();
  app.add_option("--out", opt.out, "Output folder (gbuffer/shade/reference/color.####.exr, timings.csv)")->required();
  app.add_option("--size", opt.size, "Full resolution WIDTHxHEIGHT");
  app.add_option("--fps", opt.fps, "Frames per second: frame N is the scene at N / fps seconds");
  auto* frames = app.add_option("--frames", opt.frames, "Frames A-B (inclusive); default: the whole clip");
  auto* duration = app.add_option("--duration", opt.duration, "Seconds to render from frame 0 (instead of --frames)");
  frames->excludes(duration);
  app.add_option("--camera", opt.camera, "glTF camera name or index; default: the first camera or an automatic one");
  app.add_option("--clip", opt.clip, "Animation name or index; default: the first animation");
  app.add_option("--camera-path", opt.camera_path, "fixed, or an automatic orbit | dolly camera path");
  app.add_option("--camera-period", opt.camera_period, "Seconds per orbit turn or dolly back-and-forth");
  app.add_option("--payload", opt.payload, "Payload terms: any of direct,shadow,ssao,gi");
  app.add_option("--factor", opt.factor, "Low-resolution factor k: shade is width/k x height/k");
  app.add_option("--jitter", opt.jitter, "Colour jitter: regular|halton|random|none");
  app.add_option("--shade-jitter", opt.shade_jitter, "Shade jitter: regular (k x k pattern)|halton|random|none");
  app.add_option("--reference-spp", opt.reference_spp, "Reference samples per pixel");
  app.add_option("--outputs", opt.outputs, "Outputs: any of gbuffer,shade,reference,color");
  app.add_option("--pcf", opt.pcf, "Shadow PCF kernel N (N x N shadow-map texels)");
  app.add_option("--shadow-map-size", opt.shadow_map_size, "Shadow map texels per side");
  app.add_option("--shadow-bias", opt.shadow_bias, "Shadow normal offset in shadow-map texels");
  app.add_option("--ssao-directions", opt.ssao_directions, "SSAO horizon directions");
  app.add_option("--ssao-steps", opt.ssao_steps, "SSAO steps per direction");
  app.add_option("--ssao-radius", opt.ssao_radius, "SSAO radius in world units; 0: 5% of the scene diagonal");
  app.add_option("--vpls", opt.vpls, "Virtual point lights for gi");
  app.add_option("--rsm-size", opt.rsm_size, "Reflective shadow map texels per side (VPL candidates)");
  app.add_flag("--no-mipmaps", opt.no_mipmaps, "Sample textures without mipmaps (severe undersampling)");
  app.add_option("--shade-mip-bias", opt.shade_mip_bias,
                 "Texture LOD bias of the low-res payload; auto: -log2(K), the full-res mip level");
  app.add_option("--seed", opt.seed, "Seed of random jitter, SSAO patterns and VPL sets");
  app.add_option("--compression", opt.compression, "EXR compression: zip|piz|none");
  return tool.run(argc, argv, [&]() { return run(tool, opt); });
}
