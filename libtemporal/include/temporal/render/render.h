// Deferred OpenGL renderer of animated scenes (render-gbuffer, issue 3; docs/render-gbuffer.md).
//
// One Renderer owns an OpenGL 4.5 core context - OSMesa's llvmpipe (the default and the CI path) or a device of
// EGL's device platform (Mesa's software device, or a GPU; issue 22) with every entry point loaded through the
// context's GetProcAddress - the scene's geometry and textures, and per-frame render targets. render() takes
// the scene state of this frame and of the previous frame (scene.h, FrameState, instances paired by index)
// and returns the images asked for:
//
//   gbuffer    full resolution, no jitter: depth.Z (linear view depth, background = clipFar), N.X/Y/Z (world
//              normal facing the camera), motion.X/Y (pixels, p_prev = p + motion, jitter removed, from the
//              two frames' vertex positions), id (uint32, material + 1), albedo.R/G/B (linear base colour).
//   shade      1/factor resolution per axis with this frame's shade jitter: the payload terms and their sum.
//   reference  full resolution, the same payload averaged over reference_spp jittered samples.
//   color      full resolution, one sample per pixel at the colour jitter: the payload sum (R,G,B), with
//              textures (mipmapped unless disabled) and alpha-mask cut-outs, no antialiasing.
//
// Payload (each term can be switched off; docs/render-gbuffer.md gives the equations):
//   direct.R/G/B  diffuse + Blinn-Phong specular radiance from every scene light, unshadowed
//   shadow.Y      visibility of the key light (light 0): PCF of an N x N kernel against a shadow map
//   ssao.Y        horizon-based ambient occlusion (Bavoil & Sainz 2008), D directions x S steps, pattern
//                 re-randomised every frame
//   gi.R/G/B      one-bounce indirect radiance from V virtual point lights drawn from a reflective shadow
//                 map of the key light (Dachsbacher & Stamminger 2005), no visibility (instant GI); plus a
//                 DomeLight's ambient, and the fill and ambient of the automatic rig (LightingOptions)
//   R,G,B         sum = direct * shadow + gi * ssao (a term that is off counts as 0 for direct/gi and 1
//                 for shadow/ssao)
// Background pixels: direct = gi = sum = 0, shadow = ssao = 1.
//
// Every image's metadata carries worldToCamera, worldToNDC (with that image's jitter), clipNear/Far,
// frame, fps, time, jitter (+ jitterFactor/jitterIndex on shade), cameraCut, the pass timings and
// compute_ms, and the context that made it (`temporal:glContext`, glDevice, glVendor, glRenderer, glVersion;
// docs/conventions.md). Timings are wall-clock milliseconds of the GL work of each pass, glFinish included,
// read-back excluded; with RenderOptions::gpu_timer, RenderedFrame::gpu_ms holds GL_TIME_ELAPSED times too.
#pragma once

#include "temporal/core/error.h"
#include "temporal/core/image.h"
#include "temporal/core/jitter.h"
#include "temporal/core/params.h"
#include "temporal/scene/scene.h"

#include <glm/vec3.hpp>

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace temporal {

// Pass names used in timings (`temporal:ms:<name>`, timings.csv columns).
inline constexpr const char* kPassGbuffer = "gbuffer";      // full-res G-buffer raster
inline constexpr const char* kPassLightMaps = "lightMaps";  // shadow map + reflective shadow map + VPLs
inline constexpr const char* kPassShadeLow = "shadeLow";    // low-res jittered G-buffer + payload shading
inline constexpr const char* kPassShadeFull = "shadeFull";  // payload shading of one full-res G-buffer
inline constexpr const char* kPassReference = "reference";  // all reference samples
inline constexpr const char* kPassColor = "color";          // colour: jittered full-res G-buffer + shading

struct PayloadOptions {
  bool direct = true, shadow = true, ssao = true, gi = true;
  int shadow_map_size = 2048;   // texels per side of the key light's shadow map
  int pcf_kernel = 6;           // N: PCF over N x N shadow-map texels (seed 000's jeep: 6 x 6)
  float shadow_bias = 1.5f;     // depth bias in shadow-map texels (slope-scaled by glPolygonOffset)
  int ssao_directions = 8;      // HBAO directions (seed 000's horses: 8 x 8 horizon samples)
  int ssao_steps = 8;           // HBAO steps per direction
  float ssao_radius = 0.0f;     // world units; 0: 5% of the scene's bounding-box diagonal
  int vpl_count = 2000;         // VPLs for gi (seed 000, Figure 1: 2000)
  int rsm_size = 128;           // texels per side of the reflective shadow map the VPLs are drawn from
  float vpl_clamp = 0.0f;       // minimum VPL distance (world units) against 1/d^2 spikes; 0: 2% of diagonal

  // The channel names of the enabled terms plus R,G,B.
  std::vector<std::string> channels() const;
};

// Sets the terms of `base` from "direct,shadow,ssao,gi" (any subset, any order, at least one).
Expected<PayloadOptions> parse_payload_terms(const std::string& list, PayloadOptions base = {});
// The enabled terms as parse_payload_terms reads them ("direct,shadow,ssao,gi").
std::string payload_terms_string(const PayloadOptions& payload);

struct RenderOutputs {
  bool gbuffer = true, shade = true, reference = true, color = true;
  // "gbuffer,shade,reference,color" (any subset, at least one).
  static Expected<RenderOutputs> parse(const std::string& list);
  std::string to_string() const;
};

// How the renderer gets its OpenGL context (render-gbuffer --gl).
enum class GlApi {
  OSMesa,  // llvmpipe inside the process (libOSMesa): needs no device, the CI path
  Egl,     // EGL's device platform (EGL_EXT_platform_device), surfaceless: a GPU, or Mesa's software device
  Auto,    // a hardware EGL device when one exists, else OSMesa
};
Expected<GlApi> parse_gl_api(const std::string& name);  // "osmesa", "egl", "auto"
const char* to_string(GlApi api);

// The context a renderer made (the `temporal:gl*` header attributes).
struct GlInfo {
  std::string context;                  // "osmesa" or "egl"
  int device = -1;                      // EGL device index (eglQueryDevicesEXT order); -1 for OSMesa
  std::string vendor, renderer, version;  // GL_VENDOR, GL_RENDERER, GL_VERSION
};

// One device of EGL's device platform (render-gbuffer --list-gl-devices).
struct GlDevice {
  int index = 0;
  std::string extensions;  // EGL_EXTENSIONS of the device ("EGL_MESA_device_software", "EGL_NV_device_cuda ...")
  bool software = false;   // EGL_MESA_device_software: llvmpipe, not a GPU
  // The context made on it: GL_RENDERER and GL_VERSION, or why none could be made (then renderer is empty).
  std::string renderer, version, error;
};
// Lists the EGL devices and makes a 4.5 core context on each to name its renderer. Internal error when EGL or its
// device extensions are missing; an empty list when there is no device.
Expected<std::vector<GlDevice>> list_gl_devices();

// The automatic lighting (docs/render-gbuffer.md, "Lighting"): a rig of a key, a fill and an ambient term placed
// relative to the camera at t = 0, for scenes without lights of their own (or every scene with Mode::Automatic).
// Each value is the radiance a white Lambertian surface reflects when it faces the light (so 1 = irradiance pi):
//   key      directional, travelling along -back - 1.2 up + 0.6 right of the camera (from above, behind the
//            camera's left shoulder: most visible surfaces face it); light 0: it casts the shadow and feeds the
//            RSM, so the gi bounce scales with it.
//   fill     directional, travelling along -back - 0.3 up - 1.2 right (from the camera's right, near eye level:
//            the sides the key leaves unlit); unshadowed, Lambert only; key:fill = 2.5:1, a classic three-point ratio.
//   ambient  a uniform environment of that radiance (every side, so surfaces that face away from both lights are
//            not black).
// Fill and ambient stand for the light an environment would bounce: they are part of the indirect term
// (gi.R/G/B, multiplied by ssao like a USD DomeLight), so R,G,B = direct * shadow + gi * ssao still holds, and a
// payload without gi has neither.
struct LightingOptions {
  enum class Mode {
    Scene,      // the scene's lights (and DomeLight); the rig only for a scene without lights
    Automatic,  // the rig always, in place of the scene's lights (a DomeLight's ambient is kept)
  } mode = Mode::Scene;
  float key = 1.0f;
  float fill = 0.4f;
  float ambient = 0.15f;
};
Expected<LightingOptions::Mode> parse_lighting_mode(const std::string& text);  // "scene", "auto"
const char* to_string(LightingOptions::Mode mode);

// The most reference samples per pixel: each costs about one G-buffer and full-resolution payload render (16 spp
// took about 10 minutes a frame at 1280x1024 on llvmpipe), so 4096 is already days a frame there; more (a typing
// error like 1000000) would run for as long as it is allowed (issue 26).
inline constexpr int kMaxReferenceSpp = 4096;

struct RenderOptions {
  int width = 1280, height = 1024;     // full resolution, pixels
  int factor = 4;                      // shade is width/factor x height/factor (must divide both)
  JitterMode shade_jitter = JitterMode::Regular;
  JitterMode color_jitter = JitterMode::Random;
  int reference_spp = 16;              // reference samples per pixel (Halton (2,3) sub-pixel positions), at most
                                       // kMaxReferenceSpp
  // Where the reference's samples lie in each pixel: Halton (a supersampled, antialiased reference) or None (every
  // sample at the pixel centre: only the per-sample SSAO pattern and VPL set vary, so the reference is the
  // 1-spp colour with its noise averaged - the target of methods that accumulate over frames; issue 15 item 6).
  JitterMode reference_jitter = JitterMode::Halton;
  bool mipmaps = true;                 // false: textures sampled without mipmaps (seed 003, section 7.2)
  // Texture LOD bias of the low-resolution payload's G-buffer. Unset: -log2(factor), which makes the
  // low-resolution pass pick the mip level the full-resolution pass picks, so that each jittered low-res
  // sample is a full-res pixel's sample (what temporal accumulation needs to converge to the full-res image;
  // with bias 0 the payload's textures are prefiltered for the low resolution and no upsampler can recover
  // their detail).
  std::optional<float> shade_mip_bias;
  std::uint32_t seed = 0;              // decorrelates random jitter, SSAO patterns and VPL sets
  GlApi gl = GlApi::OSMesa;            // which context (outputs are bit-identical on llvmpipe either way)
  int gl_device = -1;                  // EGL device index; -1: the first hardware device, else the first device
  // Time each pass on the device too (GL_TIME_ELAPSED queries, RenderedFrame::gpu_ms) when the device has a timer
  // that counts: not llvmpipe, whose queries read 0. Off by default: queries add a little work to every pass.
  bool gpu_timer = false;
  PayloadOptions payload;
  RenderOutputs outputs;
  LightingOptions lighting;
  // Called (the library never prints) for the first frame whose colour (else reference, else shade) image has more
  // than half of its covered pixels below 1 % of the image's maximum luminance: a render too dark to measure.
  std::function<void(const std::string&)> warning;
};

// Checks sizes, factor and payload settings without touching OpenGL (Usage errors naming the option).
Status validate(const RenderOptions& options);

// The command-line form of RenderOptions (render-gbuffer; issue 21's Param tables, temporal/core/params.h). Numbers
// and flags bind to the option fields themselves; values that are text on the command line (a size, a list of
// terms, an enum) bind to a RenderText, which starts from the options' defaults and which apply_render_text() parses.
struct RenderText {
  explicit RenderText(const RenderOptions& defaults);
  std::string size, payload, outputs, jitter, shade_jitter, reference_jitter, shade_mip_bias, gl, lights;
  double seed = 0.0;  // a uint32 (Param has no unsigned type; a double holds every uint32 exactly)
};
ParamList render_params(RenderOptions& options, RenderText& text);
// Parses `text` into `options` and validates them (Usage errors naming the option).
Status apply_render_text(const RenderText& text, RenderOptions& options);

// Command-line forms of RenderOptions fields: "WIDTHxHEIGHT" and the shade mip bias ("auto" or a number).
Status parse_size(const std::string& text, RenderOptions& options);
std::string size_string(const RenderOptions& options);
Status parse_shade_mip_bias(const std::string& text, RenderOptions& options);
std::string shade_mip_bias_string(const RenderOptions& options);

// The static part of a scene: what Scene::load returns (tests build it by hand).
struct SceneGeometry {
  const std::vector<ScenePrimitive>* primitives = nullptr;
  const std::vector<SceneMaterial>* materials = nullptr;
  const std::vector<SceneTexture>* textures = nullptr;
  glm::vec3 bounds_min{-1.0f}, bounds_max{1.0f};  // world-space bounds (SSAO radius, VPL clamp defaults)
  glm::vec3 ambient{0.0f};  // non-zero: the scene has a uniform environment (USD DomeLight), added to gi as
                            // albedo (1 - metallic) * FrameState::ambient
  // False: the scene has no lights of its own (FrameState::lights holds only scene.h's automatic key light), so the
  // renderer lights it with the automatic rig (LightingOptions). Hand-built geometries keep their lights.
  bool own_lights = true;
  // World-space directions the automatic key and fill travel, from the camera at t = 0 (LightingOptions).
  glm::vec3 key_direction{0.0f, -1.0f, 0.0f}, fill_direction{0.0f, -1.0f, 0.0f};
};

// The geometry of a loaded scene (it must outlive the renderer).
SceneGeometry geometry_of(const Scene& scene);

struct FrameInput {
  int frame = 0;
  double fps = 40.0;
  const FrameState* current = nullptr;
  const FrameState* previous = nullptr;  // state at (frame - 1) / fps; nullptr: no motion (motion = 0)
  bool camera_cut = false;               // first frame of a sequence
};

struct RenderedFrame {
  std::optional<Image> gbuffer, shade, reference, color;
  std::map<std::string, double> timings_ms;  // pass name -> ms (only the passes that ran), wall clock
  std::map<std::string, double> gpu_ms;      // pass name -> device ms (GL_TIME_ELAPSED); empty without a timer
  // Of the covered (non-background) pixels of the colour image (else reference, else shade), the fraction whose
  // luminance is below 1 % of the image's maximum (all of them when the maximum is 0); -1 without a payload image.
  double dark_fraction = -1.0;
};

class Renderer {
 public:
  // Creates the OpenGL context (RenderOptions::gl; LP_NUM_THREADS must already be set for llvmpipe), compiles
  // the shaders and uploads the scene's geometry and textures. Usage errors for bad sizes/factors; Internal when OpenGL fails.
  static Expected<Renderer> create(const RenderOptions& options, const SceneGeometry& scene);

  // Renders one frame. The FrameState's instances must refer to the SceneGeometry given to create().
  Expected<RenderedFrame> render(const FrameInput& input);

  const RenderOptions& options() const;
  // OpenGL renderer and version strings, for --verbose.
  std::string gl_description() const;
  // The context: kind, EGL device, GL vendor/renderer/version.
  const GlInfo& gl_info() const;
  // True when RenderOptions::gpu_timer is set and the device's GL_TIME_ELAPSED counts (RenderedFrame::gpu_ms).
  bool has_gpu_timer() const;

  Renderer(Renderer&&) noexcept;
  Renderer& operator=(Renderer&&) noexcept;
  ~Renderer();

 private:
  Renderer();
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The projection of a camera for an image of width x height (no jitter): glm::perspective with the
// camera's vertical field of view, the image's aspect and the camera's near/far planes.
glm::mat4 camera_projection(const CameraState& camera, int width, int height);

}  // namespace temporal
