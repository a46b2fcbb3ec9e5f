// render-gbuffer: replays an animated glTF or text USD scene with OSMesa into multi-layer EXR sequences
// (docs/render-gbuffer.md). Binds the command line to the library's option structs (whose defaults are the
// documented ones), loads the scene and runs the library's replay (temporal/render/replay.h).
#include "tool.h"

#include "temporal/core/jitter.h"
#include "temporal/render/replay.h"
#include "temporal/scene/scene.h"

#include <cstdlib>
#include <optional>

using namespace temporal;

namespace {

// The options whose command-line form is text the library parses; each starts as the library's default.
struct TextOptions {
  explicit TextOptions(const RenderOptions& r, const SceneLoadOptions& l, const ReplayOptions& p)
      : size(size_string(r)), payload(payload_terms_string(r.payload)), outputs(r.outputs.to_string()),
        jitter(to_string(r.color_jitter)), shade_jitter(to_string(r.shade_jitter)), reference_jitter(to_string(r.reference_jitter)), shade_mip_bias(shade_mip_bias_string(r)),
        camera_path(camera_path_name(l.camera.path)), compression(compression_name(p.compression)), mipmaps_off(!r.mipmaps) {}
  std::string scene, size, payload, outputs, jitter, shade_jitter, reference_jitter, shade_mip_bias, camera_path, compression, frames;
  bool mipmaps_off;
};

Status apply(const TextOptions& t, RenderOptions& r, SceneLoadOptions& l, ReplayOptions& p) {
  if (auto s = parse_size(t.size, r); !s) return s;
  auto payload = parse_payload_terms(t.payload, r.payload);
  if (!payload) return payload.error();
  r.payload = *payload;
  auto outputs = RenderOutputs::parse(t.outputs);
  if (!outputs) return outputs.error();
  r.outputs = *outputs;
  auto color = parse_jitter_mode(t.jitter);
  if (!color) return color.error();
  auto shade = parse_jitter_mode(t.shade_jitter);
  if (!shade) return shade.error();
  auto reference = parse_jitter_mode(t.reference_jitter);
  if (!reference) return reference.error();
  r.color_jitter = *color;
  r.shade_jitter = *shade;
  r.reference_jitter = *reference;
  auto compression = parse_replay_compression(t.compression);
  if (!compression) return compression.error();
  p.compression = *compression;
  if (auto s = parse_shade_mip_bias(t.shade_mip_bias, r); !s) return s;
  r.mipmaps = !t.mipmaps_off;
  auto path = parse_camera_path(t.camera_path);
  if (!path) return path.error();
  l.camera.path = *path;
  if (auto s = validate(p); !s) return s;
  return validate(r);
}

Status run(const tool::Tool& tool, const TextOptions& text, RenderOptions render, SceneLoadOptions load, ReplayOptions replay) {
  if (auto s = apply(text, render, load, replay); !s) return s;
  auto scene = Scene::load(text.scene, load);
  if (!scene) return scene.error();
  for (const std::string& w : scene->warnings()) tool.log("warning: " + w);
  if (!text.frames.empty()) {
    auto range = FrameRange::parse(text.frames);
    if (!range) return range.error();
    replay.frames = *range;
  }
  // llvmpipe reads LP_NUM_THREADS when the context is created.
  if (tool.threads() > 0) setenv("LP_NUM_THREADS", std::to_string(tool.threads()).c_str(), 1);
  replay.tool = tool.signature();
  replay.parameters = tool.command_line();
  std::optional<tool::Progress> progress;
  ReplayHooks hooks;
  hooks.log = [&](const std::string& line) { tool.log(line); };
  hooks.frame_done = [&](int frame, int /*done*/, int total) {
    if (!progress) progress.emplace(tool.name(), total);
    progress->step(frame);
  };
  return temporal::replay(*scene, render, replay, hooks);
}

}  // namespace

int main(int argc, char** argv) {
  tool::Tool tool("render-gbuffer",
                  "Replays an animated glTF 2.0 or text USD scene with OSMesa (llvmpipe) into multi-layer EXR sequences:\n"
                  "G-buffer, low-resolution jittered payload, supersampled reference and 1-spp colour.");
  RenderOptions r;
  SceneLoadOptions l;
  ReplayOptions p;
  TextOptions t(r, l, p);
  PayloadOptions& pl = r.payload;
  auto& app = tool.app();
  app.add_option("scene", t.scene, "glTF 2.0 (.gltf, .glb) or text USD (.usda, .usd) scene")->required();
  app.add_option("--out", p.out_dir, "Output folder (gbuffer/shade/reference/color.####.exr, timings.csv)")->required();
  app.add_option("--size", t.size, "Full resolution WIDTHxHEIGHT");
  app.add_option("--fps", p.fps, "Frames per second: frame N is the scene at N / fps seconds");
  auto* frames = app.add_option("--frames", t.frames, "Frames A-B (inclusive); default: the whole clip");
  auto* duration = app.add_option("--duration", p.duration_s, "Seconds to render from frame 0 (instead of --frames)");
  frames->excludes(duration);
  app.add_option("--camera", l.camera.camera, "Camera name, index or USD prim path; default: the first camera or an automatic one");
  app.add_option("--clip", l.clip, "glTF animation name or index; default: the first animation");
  app.add_option("--camera-path", t.camera_path, "fixed, or an automatic orbit | dolly camera path");
  app.add_option("--camera-period", l.camera.path_period_s, "Seconds per orbit turn or dolly back-and-forth");
  app.add_option("--payload", t.payload, "Payload terms: any of direct,shadow,ssao,gi");
  app.add_option("--factor", r.factor, "Low-resolution factor k: shade is width/k x height/k");
  app.add_option("--jitter", t.jitter, "Colour jitter: regular|regular-raster|halton|random|none");
  app.add_option("--shade-jitter", t.shade_jitter, "Shade jitter: regular (k x k pattern, dispersed order)|regular-raster (raster order)|halton|random|none");
  app.add_option("--reference-spp", r.reference_spp, "Reference samples per pixel");
  app.add_option("--reference-jitter", t.reference_jitter,
                 "Reference sample positions: halton (supersampled) | none (pixel centres: the colour with its SSAO/VPL noise averaged)");
  app.add_option("--outputs", t.outputs, "Outputs: any of gbuffer,shade,reference,color");
  app.add_option("--pcf", pl.pcf_kernel, "Shadow PCF kernel N (N x N shadow-map texels)");
  app.add_option("--shadow-map-size", pl.shadow_map_size, "Shadow map texels per side");
  app.add_option("--shadow-bias", pl.shadow_bias, "Shadow normal offset in shadow-map texels");
  app.add_option("--ssao-directions", pl.ssao_directions, "SSAO horizon directions");
  app.add_option("--ssao-steps", pl.ssao_steps, "SSAO steps per direction");
  app.add_option("--ssao-radius", pl.ssao_radius, "SSAO radius in world units; 0: 5% of the scene diagonal");
  app.add_option("--vpls", pl.vpl_count, "Virtual point lights for gi");
  app.add_option("--rsm-size", pl.rsm_size, "Reflective shadow map texels per side (VPL candidates)");
  app.add_flag("--no-mipmaps", t.mipmaps_off, "Sample textures without mipmaps (severe undersampling)");
  app.add_option("--shade-mip-bias", t.shade_mip_bias, "Texture LOD bias of the low-res payload; auto: -log2(K), the full-res mip level");
  app.add_option("--seed", r.seed, "Seed of random jitter, SSAO patterns and VPL sets");
  app.add_option("--compression", t.compression, "EXR compression: zip|piz|none");
  return tool.run(argc, argv, [&]() { return run(tool, t, r, l, p); });
}
