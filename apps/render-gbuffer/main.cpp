// render-gbuffer: replays an animated glTF or text USD scene with OpenGL (OSMesa's llvmpipe, or an EGL device such as
// a GPU) into multi-layer EXR sequences (docs/render-gbuffer.md). Binds the command line to the library's option
// structs through Param tables (whose defaults are the documented ones), loads the scene and runs the library's
// replay (temporal/replay/replay.h).
#include "tool.h"

#include "temporal/replay/replay.h"
#include "temporal/scene/scene.h"

#include <cstdlib>
#include <iostream>
#include <optional>

using namespace temporal;

namespace {

// The scene and replay options: numbers bind to the option structs, text forms to this struct (each starts as the
// library's default).
struct SequenceText {
  explicit SequenceText(const SceneLoadOptions& l, const ReplayOptions& p)
      : camera_path(camera_path_name(l.camera.path)), compression(compression_name(p.compression)) {}
  std::string scene, camera_path, compression, frames;
};

ParamList sequence_params(SceneLoadOptions& l, ReplayOptions& p, SequenceText& t) {
  // Finite ranges whose arithmetic stays finite (issue 26): a frame's time N / fps with N < 2^31 and fps >= 0.001 is
  // at most 2.2e12 s (a rate of 1e-45 made it inf); an orbit's angle 2 pi t / period likewise; duration * fps is
  // further bounded by validate(ReplayOptions) to a million frames.
  Param fps{"--fps", "Frames per second: frame N is the scene at N / fps seconds", &p.fps, 0.001, 10000.0};
  // Scene::load checks the period where a path uses it; a fixed camera ignores it.
  Param period{"--camera-period", "Seconds per orbit turn or dolly back-and-forth", &l.camera.path_period_s, 0.001, 1e6};
  return {
      fps,
      Param::text("--frames", "Frames A-B (inclusive); default: the whole clip", &t.frames),
      Param{"--duration", "Seconds to render from frame 0 (instead of --frames; duration x fps <= 1e6 frames)",
            &p.duration_s, 0.0, 1e9},
      Param::text("--camera", "Camera name, index or USD prim path; default: the first camera or an automatic one",
                  &l.camera.camera),
      Param::text("--clip", "glTF animation name or index; default: the first animation", &l.clip),
      Param::choice("--camera-path", "fixed, or an automatic orbit | dolly camera path", &t.camera_path,
                    {"fixed", "orbit", "dolly"}),
      period,
      Param::choice("--compression", "EXR compression", &t.compression, {"zip", "piz", "none"}),
  };
}

Status apply_sequence_text(const SequenceText& t, SceneLoadOptions& l, ReplayOptions& p) {
  auto compression = parse_replay_compression(t.compression);
  if (!compression) return compression.error();
  p.compression = *compression;
  auto path = parse_camera_path(t.camera_path);
  if (!path) return path.error();
  l.camera.path = *path;
  if (!t.frames.empty()) {
    auto range = FrameRange::parse(t.frames);
    if (!range) return range.error();
    p.frames = *range;
  }
  return validate(p);
}

// --list-gl-devices: one line per EGL device (index, kind, renderer of a context made on it, its extensions).
Status list_devices() {
  auto devices = list_gl_devices();
  if (!devices) return devices.error();
  if (devices->empty()) std::cerr << "render-gbuffer: EGL finds no device (--gl osmesa still works)\n";
  for (const GlDevice& d : *devices) {
    std::cout << d.index << '\t' << (d.software ? "software" : "hardware") << '\t'
              << (d.error.empty() ? d.renderer + " | " + d.version : "no OpenGL 4.5 core context: " + d.error) << '\t'
              << d.extensions << '\n';
  }
  return {};
}

}  // namespace

int main(int argc, char** argv) {
  tool::Tool tool("render-gbuffer",
                  "Replays an animated glTF 2.0 or text USD scene with OpenGL - OSMesa's llvmpipe, or a GPU through EGL "
                  "(--gl) - into multi-layer EXR sequences:\n"
                  "G-buffer, low-resolution jittered payload, supersampled reference and 1-spp colour.");
  RenderOptions r;
  SceneLoadOptions l;
  ReplayOptions p;
  RenderText rt(r);
  SequenceText st(l, p);
  auto& app = tool.app();
  app.add_option("scene", st.scene, "glTF 2.0 (.gltf, .glb) or text USD (.usda, .usd) scene")->required();
  app.add_option("--out", p.out_dir, "Output folder (gbuffer/shade/reference/color.####.exr, timings.csv)")->required();
  tool.add_output(&p.out_dir, true);
  tool.add_params(sequence_params(l, p, st));
  tool.add_params(render_params(r, rt));
  app.get_option("--frames")->excludes("--duration");
  // Lists and exits before the required scene and --out are checked (CLI11 runs flag callbacks first).
  bool listed = false;
  app.add_flag_callback(
      "--list-gl-devices",
      [&] {
        listed = true;
        throw CLI::Success();
      },
      "Print the EGL devices (index, software|hardware, the renderer of a 4.5 core context on it, EGL extensions; "
      "tab-separated, one per line) and exit");
  int rc = tool.run(argc, argv, [&]() -> Status {
    if (auto s = apply_sequence_text(st, l, p); !s) return s;
    if (auto s = apply_render_text(rt, r); !s) return s;
    auto scene = Scene::load(st.scene, l);
    if (!scene) return scene.error();
    for (const std::string& w : scene->warnings()) tool.log("warning: " + w);
    // llvmpipe reads LP_NUM_THREADS when the context is created.
    if (tool.threads() > 0) setenv("LP_NUM_THREADS", std::to_string(tool.threads()).c_str(), 1);
    p.tool = tool.signature();
    p.parameters = tool.command_line();
    std::optional<tool::Progress> progress;
    r.warning = [&](const std::string& message) { tool.print_warning("", message); };
    ReplayHooks hooks;
    hooks.log = [&](const std::string& line) { tool.log(line); };
    hooks.frame_done = [&](int frame, int /*done*/, int total) {
      if (!progress) progress.emplace(tool.name(), total);
      progress->step(frame);
    };
    return temporal::replay(*scene, r, p, hooks);
  });
  if (!listed) return rc;
  // Listed outside Tool::run's body (the parse stopped at CLI::Success); errors map to the same exit codes.
  if (Status s = list_devices(); !s) {
    tool.print_error(s.error());
    return tool::exit_code_for(s.error());
  }
  return tool::kExitOk;
}
