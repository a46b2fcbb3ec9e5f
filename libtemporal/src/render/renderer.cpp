// render-gbuffer's frame loop in OpenGL (OSMesa's llvmpipe or an EGL device, gl_api.h): light maps, G-buffers,
// deferred payload shading, read-back into planar images. docs/render-gbuffer.md explains every choice made here.
#include "temporal/render/render.h"

#include "gl_api.h"
#include "scene_gpu.h"
#include "shaders.h"

#include "temporal/core/parallel.h"

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

namespace temporal {

using namespace render_detail;

SceneGeometry geometry_of(const Scene& scene) {
  SceneGeometry g;
  g.primitives = &scene.primitives();
  g.materials = &scene.materials();
  g.textures = &scene.textures();
  g.bounds_min = scene.bounds_min();
  g.bounds_max = scene.bounds_max();
  g.ambient = scene.ambient();
  // The automatic rig's directions from the camera at t = 0 (render.h LightingOptions); the key is scene.h's
  // automatic key light, computed the same way (scene_finish.cpp).
  const FrameState first = scene.evaluate(0.0);
  const glm::mat4 cam_to_world = glm::inverse(first.camera.view);
  const glm::vec3 right(cam_to_world[0]), up(cam_to_world[1]), back(cam_to_world[2]);
  g.key_direction = glm::normalize(-back * 1.0f - up * 1.2f + right * 0.6f);
  g.fill_direction = glm::normalize(-back * 1.0f - up * 0.3f - right * 1.2f);
  // Scene has no "has lights" flag: a scene without lights evaluates to exactly the automatic key light scene.h
  // documents (one white directional light of intensity pi along that direction), which a scene's own light
  // matches only by coincidence of every value.
  if (first.lights.size() == 1) {
    const LightState& l = first.lights.front();
    g.own_lights = !(l.type == LightState::Type::Directional && l.color == glm::vec3(1.0f) &&
                     l.intensity == 3.14159265f && l.range == 0.0f &&
                     glm::length(l.direction - g.key_direction) < 1e-5f);
  }
  return g;
}

glm::mat4 camera_projection(const CameraState& camera, int width, int height) {
  // The image's aspect wins over the camera's (glTF leaves letterboxing to the viewer); a non-positive far
  // plane (glTF's infinite projection) is replaced by 1000 x near so depth stays finite.
  const float aspect = float(width) / float(height);
  const float znear = camera.znear > 0.0f ? camera.znear : 0.01f;
  const float zfar = camera.zfar > znear ? camera.zfar : 1000.0f * znear;
  return glm::perspective(camera.yfov, aspect, znear, zfar);
}

// ---- GPU resources ---------------------------------------------------------------------------------------

namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

GLuint make_texture(const GlFunctions& gl, GLenum format, int w, int h, GLint filter = GL_NEAREST) {
  GLuint t = 0;
  gl.GenTextures(1, &t);
  gl.BindTexture(GL_TEXTURE_2D, t);
  gl.TexStorage2D(GL_TEXTURE_2D, 1, format, w, h);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, filter);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, filter);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  return t;
}

// A framebuffer with colour attachments 0..n-1 and an optional depth attachment.
struct Fbo {
  GLuint fbo = 0;
  std::vector<GLuint> colors;
  GLuint depth = 0;
  int width = 0, height = 0;
};

Expected<Fbo> make_fbo(const GlFunctions& gl, int w, int h, const std::vector<GLenum>& formats, bool depth,
                       const char* name) {
  Fbo f;
  f.width = w;
  f.height = h;
  gl.GenFramebuffers(1, &f.fbo);
  gl.BindFramebuffer(GL_FRAMEBUFFER, f.fbo);
  std::vector<GLenum> buffers;
  for (std::size_t i = 0; i < formats.size(); ++i) {
    f.colors.push_back(make_texture(gl, formats[i], w, h));
    gl.FramebufferTexture2D(GL_FRAMEBUFFER, GLenum(GL_COLOR_ATTACHMENT0 + i), GL_TEXTURE_2D, f.colors.back(), 0);
    buffers.push_back(GLenum(GL_COLOR_ATTACHMENT0 + i));
  }
  if (depth) {
    f.depth = make_texture(gl, GL_DEPTH_COMPONENT32F, w, h);
    gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, f.depth, 0);
  }
  if (buffers.empty()) {
    const GLenum none = GL_NONE;
    gl.DrawBuffers(1, &none);
  } else {
    gl.DrawBuffers(GLsizei(buffers.size()), buffers.data());
  }
  const GLenum status = gl.CheckFramebufferStatus(GL_FRAMEBUFFER);
  gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
  if (status != GL_FRAMEBUFFER_COMPLETE)
    return Error::usage(std::string("OpenGL cannot make the ") + std::to_string(w) + "x" + std::to_string(h) + " " + name +
                        " framebuffer (status " + std::to_string(status) +
                        "): the image is beyond what the OpenGL device can allocate here; reduce --size");
  return f;
}

void delete_fbo(const GlFunctions& gl, Fbo& f) {
  if (!f.fbo) return;
  gl.DeleteFramebuffers(1, &f.fbo);
  if (!f.colors.empty()) gl.DeleteTextures(GLsizei(f.colors.size()), f.colors.data());
  if (f.depth) gl.DeleteTextures(1, &f.depth);
  f = {};
}

// G-buffer attachments (shaders.cpp, kGbufferFragment).
enum GbufferAttachment { kAlbedo = 0, kNormal = 1, kMotion = 2, kWorld = 3, kId = 4 };
// Motion is RGBA32F: motion.X/Y and prevDepth.Z (the fourth component is unused).
const std::vector<GLenum> kGbufferFormats = {GL_RGBA32F, GL_RGBA32F, GL_RGBA32F, GL_RGBA32F, GL_R32UI};
// Shade attachments: direct + shadow, gi + ssao, sum.
const std::vector<GLenum> kShadeFormats = {GL_RGBA32F, GL_RGBA32F, GL_RGBA32F};
const std::vector<GLenum> kRsmFormats = {GL_RGBA32F, GL_RGBA32F, GL_RGBA32F};

// The key light's camera for the shadow map and the reflective shadow map.
struct LightView {
  glm::mat4 view_proj{1.0f};
  glm::vec3 axis{0.0f, -1.0f, 0.0f};
  float texel_world = 0.0f;    // world size of a shadow-map texel near the scene centre
  float rsm_measure = 0.0f;    // directional: world area of an RSM texel; else solid angle of the centre texel
};

// The instant of frame N at `fps` in microseconds (wrapping after 71 minutes): the key of every random pattern.
// Rates whose frames share instants (40 Hz frame n, 120 Hz frame 3n) get the same key.
std::uint32_t instant_key(int frame, double fps) {
  return std::uint32_t(std::uint64_t(std::llround(double(frame) / fps * 1e6)));
}

// The index frame_jitter() hashes or walks: random jitter is keyed by the instant; the regular and Halton patterns
// walk their sequence with the frame number (their order is what makes them regular or low-discrepancy).
int jitter_frame(JitterMode mode, int frame, std::uint32_t instant) {
  return mode == JitterMode::Random ? int(instant & 0x7fffffffu) : frame;
}

}  // namespace

struct Renderer::Impl {
  RenderOptions options;
  SceneGeometry scene;
  std::unique_ptr<GlContext> context;
  std::unique_ptr<SceneGpu> gpu;
  GLuint gbuffer_program = 0, shadow_program = 0, rsm_program = 0, shade_program = 0;
  GLuint empty_vao = 0, vpl_buffer = 0;
  Fbo gbuffer_full, gbuffer_low, shade_full, shade_low, shadow_map, rsm;
  float scene_diagonal = 1.0f;
  // The automatic rig (LightingOptions) lights this scene: its key replaces the scene's lights.
  bool rig = false;
  std::vector<LightState> rig_lights;
  bool dark_warned = false;  // RenderOptions::warning is called for the first dark frame only

  // Per frame.
  const FrameState* state = nullptr;
  LightView light;
  std::vector<float> rsm_position, rsm_normal, rsm_flux;  // read back once per frame
  std::vector<std::uint32_t> rsm_valid;
  std::vector<float> vpl_scratch;
  std::vector<float> readback;
  std::vector<std::uint32_t> readback_u;
  // GL_TIME_ELAPSED queries (RenderOptions::gpu_timer on a device whose timer counts): two, because the colour
  // pass times its G-buffer and its shading apart and elapsed-time queries cannot nest.
  bool timer = false;
  GLuint queries[2] = {0, 0};

  const GlFunctions& gl() const { return context->gl(); }
  ~Impl();
  Status init();
  // The lights of this frame: the rig's key, or the scene's.
  const std::vector<LightState>& lights() const { return rig ? rig_lights : state->lights; }
  void set_lights(GLuint program) const;
  Status light_maps(const FrameState& state);
  void select_vpls(std::uint32_t instant, int sample);
  struct View {
    glm::mat4 view{1.0f}, proj{1.0f}, proj_jittered{1.0f}, prev_vp{1.0f}, prev_view{1.0f};
    glm::vec3 camera_pos{0.0f};
    float znear = 0.1f, zfar = 100.0f;
  };
  View make_view(const FrameInput& in, int w, int h, glm::vec2 jitter) const;
  void draw_gbuffer(const Fbo& target, const View& v, float lod_bias = 0.0f);
  void shade(const Fbo& gbuffer, const Fbo& target, const View& v, std::uint32_t seed, bool accumulate,
             bool clear);
  void read_rgba(const Fbo& f, int attachment, int components);
  void read_uint(const Fbo& f, int attachment);
  Image gbuffer_image(const Fbo& f, const View& v, const FrameInput& in);
  // Also sets `dark` to RenderedFrame::dark_fraction of the sum it reads.
  Image shade_image(const Fbo& f, float scale, double* dark = nullptr);
  void set_metadata(Image& image, const FrameInput& in, const View& v, glm::vec2 jitter) const;
  // The passes of Renderer::render, in their order.
  Status pass_light_maps(const FrameInput& in, RenderedFrame& result);
  void pass_gbuffer(const FrameInput& in, const View& full, RenderedFrame& result);
  void pass_shade_low(const FrameInput& in, std::uint32_t instant, std::uint32_t frame_seed, RenderedFrame& result);
  void pass_color(const FrameInput& in, std::uint32_t instant, std::uint32_t frame_seed, RenderedFrame& result);
  void pass_reference(const FrameInput& in, const View& full, std::uint32_t instant, RenderedFrame& result);
  void warn_if_dark(const FrameInput& in, double dark_fraction);
  void timer_begin(int slot) const {
    if (timer) gl().BeginQuery(GL_TIME_ELAPSED, queries[slot]);
  }
  void timer_end() const {
    if (timer) gl().EndQuery(GL_TIME_ELAPSED);
  }
  // The device time of the query in `slot` (waits for it).
  double timer_ms(int slot) const {
    GLuint64 ns = 0;
    gl().GetQueryObjectui64v(queries[slot], GL_QUERY_RESULT, &ns);
    return double(ns) / 1e6;
  }
};

Renderer::Impl::~Impl() {
  if (!context) return;
  context->make_current();  // another renderer's context may have taken the thread since
  const auto& g = gl();
  if (queries[0]) g.DeleteQueries(2, queries);
  gpu.reset();
  for (Fbo* f : {&gbuffer_full, &gbuffer_low, &shade_full, &shade_low, &shadow_map, &rsm}) delete_fbo(g, *f);
  for (GLuint p : {gbuffer_program, shadow_program, rsm_program, shade_program})
    if (p) g.DeleteProgram(p);
  if (empty_vao) g.DeleteVertexArrays(1, &empty_vao);
  if (vpl_buffer) g.DeleteBuffers(1, &vpl_buffer);
}

Status Renderer::Impl::init() {
  const auto& g = gl();
  const PayloadOptions& p = options.payload;
  auto build = [&](const char* name, const std::string& vs, const std::string& fs, GLuint& out) -> Status {
    auto prog = build_program(g, name, vs, fs);
    if (!prog) return prog.error();
    out = *prog;
    return {};
  };
  if (auto s = build("gbuffer", kGeometryVertex, kGbufferFragment, gbuffer_program); !s) return s;
  if (auto s = build("shadow", kGeometryVertex, kShadowFragment, shadow_program); !s) return s;
  if (auto s = build("rsm", kGeometryVertex, kRsmFragment, rsm_program); !s) return s;
  rig = options.lighting.mode == LightingOptions::Mode::Automatic || !scene.own_lights;
  if (rig) {
    LightState key;
    key.type = LightState::Type::Directional;
    key.direction = scene.key_direction;
    key.color = glm::vec3(1.0f);
    key.intensity = 3.14159265f * options.lighting.key;
    rig_lights = {key};
  }
  const bool ambient = scene.ambient != glm::vec3(0.0f) || rig;
  if (auto s = build("shade", kFullscreenVertex, deferred_fragment(p.direct, p.shadow, p.ssao, p.gi, ambient, rig), shade_program); !s)
    return s;
  g.GenVertexArrays(1, &empty_vao);
  g.GenBuffers(1, &vpl_buffer);

  const int w = options.width, h = options.height, k = options.factor;
  const RenderOutputs& o = options.outputs;
  auto fbo = [&](Fbo& out, int fw, int fh, const std::vector<GLenum>& formats, bool depth, const char* name) -> Status {
    auto f = make_fbo(g, fw, fh, formats, depth, name);
    if (!f) return f.error();
    out = *f;
    return {};
  };
  if (o.gbuffer || o.reference || o.color)
    if (auto s = fbo(gbuffer_full, w, h, kGbufferFormats, true, "gbuffer"); !s) return s;
  if (o.reference || o.color)
    if (auto s = fbo(shade_full, w, h, kShadeFormats, false, "shade (full)"); !s) return s;
  if (o.shade) {
    if (auto s = fbo(gbuffer_low, w / k, h / k, kGbufferFormats, true, "gbuffer (low)"); !s) return s;
    if (auto s = fbo(shade_low, w / k, h / k, kShadeFormats, false, "shade (low)"); !s) return s;
  }
  const bool payload_shading = o.shade || o.reference || o.color;
  if (payload_shading && p.shadow) {
    if (auto s = fbo(shadow_map, p.shadow_map_size, p.shadow_map_size, {}, true, "shadow map"); !s) return s;
    g.BindTexture(GL_TEXTURE_2D, shadow_map.depth);
    g.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
    g.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
    g.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    g.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  }
  if (payload_shading && p.gi)
    if (auto s = fbo(rsm, p.rsm_size, p.rsm_size, kRsmFormats, true, "reflective shadow map"); !s) return s;

  gpu = std::make_unique<SceneGpu>(g, scene, options.mipmaps);
  if (auto s = gpu->upload(); !s) return s;
  scene_diagonal = std::max(glm::length(scene.bounds_max - scene.bounds_min), 1e-3f);
  if (options.gpu_timer) {
    // llvmpipe (and softpipe) accept timer queries but answer 0: a software device has wall time only.
    GLint bits = 0;
    g.GetQueryiv(GL_TIME_ELAPSED, GL_QUERY_COUNTER_BITS, &bits);
    const std::string& renderer = context->info().renderer;
    const bool software = renderer.rfind("llvmpipe", 0) == 0 || renderer.rfind("softpipe", 0) == 0;
    timer = bits > 0 && !software;
    if (timer) g.GenQueries(2, queries);
  }
  return check_gl(g, "renderer setup");
}

void Renderer::Impl::set_lights(GLuint program) const {
  const auto& g = gl();
  const std::vector<LightState>& all = lights();
  const int n = std::min<int>(int(all.size()), kMaxLights);
  g.Uniform1i(g.GetUniformLocation(program, "u_light_count"), n);
  for (int i = 0; i < n; ++i) {
    const LightState& l = all[std::size_t(i)];
    auto loc = [&](const char* name) {
      return g.GetUniformLocation(program, (std::string(name) + "[" + std::to_string(i) + "]").c_str());
    };
    const int type = l.type == LightState::Type::Directional ? 0 : l.type == LightState::Type::Point ? 1 : 2;
    const glm::vec3 dir = glm::length(l.direction) > 0 ? glm::normalize(l.direction) : glm::vec3(0, -1, 0);
    const glm::vec3 c = l.color * l.intensity;
    g.Uniform1i(loc("u_light_type"), type);
    g.Uniform3f(loc("u_light_position"), l.position.x, l.position.y, l.position.z);
    g.Uniform3f(loc("u_light_direction"), dir.x, dir.y, dir.z);
    g.Uniform3f(loc("u_light_color"), c.x, c.y, c.z);
    g.Uniform1f(loc("u_light_range"), l.range);
    g.Uniform2f(loc("u_light_cone"), std::cos(l.outer_cone), std::cos(l.inner_cone));
  }
}

// Shadow map and reflective shadow map of the key light (light 0), both from one light camera fitted to
// this frame's geometry: directional lights get an orthographic box around the bounding sphere, spot lights
// their cone, point lights a cone towards the scene (one face only: see docs).
Status Renderer::Impl::light_maps(const FrameState& state) {
  const auto& g = gl();
  const PayloadOptions& p = options.payload;
  if (lights().empty()) return Error::internal("the scene evaluated without lights (scene.h promises a key light)");
  const LightState& key = lights().front();
  const glm::vec3 lo = gpu->frame_min(), hi = gpu->frame_max();
  const glm::vec3 centre = 0.5f * (lo + hi);
  const float radius = std::max(0.5f * glm::length(hi - lo), 1e-3f);
  auto up_for = [](glm::vec3 axis) {
    return std::abs(axis.y) > 0.99f ? glm::vec3(0, 0, 1) : glm::vec3(0, 1, 0);
  };
  LightView lv;
  if (key.type == LightState::Type::Directional) {
    const glm::vec3 dir = glm::length(key.direction) > 0 ? glm::normalize(key.direction) : glm::vec3(0, -1, 0);
    const glm::mat4 view = glm::lookAt(centre - dir * (2.0f * radius), centre, up_for(dir));
    const glm::mat4 proj = glm::ortho(-radius, radius, -radius, radius, radius * 0.5f, radius * 3.5f);
    lv.view_proj = proj * view;
    lv.axis = dir;
    lv.texel_world = 2.0f * radius / float(p.shadow_map_size);
    const float rsm_texel = 2.0f * radius / float(p.rsm_size);
    lv.rsm_measure = rsm_texel * rsm_texel;
  } else {
    const glm::vec3 to_centre = centre - key.position;
    const float dist = glm::length(to_centre);
    glm::vec3 axis = key.type == LightState::Type::Spot && glm::length(key.direction) > 0
                         ? glm::normalize(key.direction)
                         : (dist > 1e-6f ? to_centre / dist : glm::vec3(0, -1, 0));
    float fov;
    if (key.type == LightState::Type::Spot) fov = std::min(2.0f * key.outer_cone, glm::radians(170.0f));
    else fov = dist > radius ? std::min(2.0f * std::asin(radius / dist) * 1.1f, glm::radians(150.0f)) : glm::radians(150.0f);
    const float znear = std::max(dist - radius, 0.01f * radius);
    const float zfar = dist + radius;
    const glm::mat4 view = glm::lookAt(key.position, key.position + axis, up_for(axis));
    lv.view_proj = glm::perspective(fov, 1.0f, znear, zfar) * view;
    lv.axis = axis;
    const float t = 2.0f * std::tan(0.5f * fov);
    lv.texel_world = std::max(dist, radius) * t / float(p.shadow_map_size);
    lv.rsm_measure = (t / float(p.rsm_size)) * (t / float(p.rsm_size));
  }
  light = lv;
  const glm::mat4 identity(1.0f);

  auto geometry_uniforms = [&](GLuint prog) {
    g.UseProgram(prog);
    g.UniformMatrix4fv(g.GetUniformLocation(prog, "u_view_proj"), 1, GL_FALSE, glm::value_ptr(lv.view_proj));
    g.UniformMatrix4fv(g.GetUniformLocation(prog, "u_cur_vp"), 1, GL_FALSE, glm::value_ptr(lv.view_proj));
    g.UniformMatrix4fv(g.GetUniformLocation(prog, "u_prev_vp"), 1, GL_FALSE, glm::value_ptr(lv.view_proj));
    g.UniformMatrix4fv(g.GetUniformLocation(prog, "u_view"), 1, GL_FALSE, glm::value_ptr(identity));
  };
  g.Enable(GL_DEPTH_TEST);
  g.DepthFunc(GL_LESS);
  g.DepthMask(GL_TRUE);
  const float one = 1.0f;
  if (shadow_map.fbo) {
    g.BindFramebuffer(GL_FRAMEBUFFER, shadow_map.fbo);
    g.Viewport(0, 0, shadow_map.width, shadow_map.height);
    g.ClearBufferfv(GL_DEPTH, 0, &one);
    geometry_uniforms(shadow_program);
    // Slope-scaled bias against acne; the shading side adds a normal offset of shadow_bias texels.
    g.Enable(GL_POLYGON_OFFSET_FILL);
    g.PolygonOffset(1.5f, 2.0f);
    gpu->draw_all(shadow_program, false);  // both faces: thin single-sided geometry still casts
    g.Disable(GL_POLYGON_OFFSET_FILL);
  }
  if (rsm.fbo) {
    g.BindFramebuffer(GL_FRAMEBUFFER, rsm.fbo);
    g.Viewport(0, 0, rsm.width, rsm.height);
    const float zero[4] = {0, 0, 0, 0};
    for (int i = 0; i < 3; ++i) g.ClearBufferfv(GL_COLOR, i, zero);
    g.ClearBufferfv(GL_DEPTH, 0, &one);
    geometry_uniforms(rsm_program);
    set_lights(rsm_program);
    g.Uniform1f(g.GetUniformLocation(rsm_program, "u_texel_measure"), lv.rsm_measure);
    g.Uniform3f(g.GetUniformLocation(rsm_program, "u_light_axis"), lv.axis.x, lv.axis.y, lv.axis.z);
    gpu->draw_all(rsm_program, true);
    // The RSM is small (rsm_size^2 texels): read it back once, draw VPL sets from it on the CPU.
    const std::size_t n = std::size_t(rsm.width) * std::size_t(rsm.height);
    for (auto [att, dst] : {std::pair{0, &rsm_position}, std::pair{1, &rsm_normal}, std::pair{2, &rsm_flux}}) {
      dst->resize(n * 4);
      g.ReadBuffer(GLenum(GL_COLOR_ATTACHMENT0 + att));
      g.ReadPixels(0, 0, rsm.width, rsm.height, GL_RGBA, GL_FLOAT, dst->data());
    }
    rsm_valid.clear();
    for (std::size_t i = 0; i < n; ++i)
      if (rsm_position[i * 4 + 3] > 0.0f) rsm_valid.push_back(std::uint32_t(i));
  }
  g.Disable(GL_DEPTH_TEST);
  g.BindFramebuffer(GL_FRAMEBUFFER, 0);
  return check_gl(g, "light maps");
}

// A new set of VPLs: vpl_count RSM texels drawn uniformly (with replacement) among the lit ones, each
// carrying its reflected flux times (lit texels / vpl_count), so the sum estimates the whole RSM's
// one-bounce light without bias. The set changes every frame and every reference sample (seed 000 relies
// on accumulating this noise over time).
void Renderer::Impl::select_vpls(std::uint32_t instant, int sample) {
  if (!rsm.fbo) return;
  const int count = rsm_valid.empty() ? 0 : options.payload.vpl_count;
  vpl_scratch.assign(std::size_t(kMaxVpls) * 8, 0.0f);
  const float scale = count > 0 ? float(rsm_valid.size()) / float(count) : 0.0f;
  for (int i = 0; i < count; ++i) {
    const std::uint32_t r = hash_u32(options.seed, instant, std::uint32_t(sample) + 0x5151u, std::uint32_t(i));
    const std::size_t t = rsm_valid[r % rsm_valid.size()];
    // Packed as the shader reads it (shaders.cpp, Vpls): (position, n.x), (flux with sign(n.z) on r, n.y).
    float* v = &vpl_scratch[std::size_t(i) * 8];
    const float* pos = &rsm_position[t * 4];
    const float* nrm = &rsm_normal[t * 4];
    const float* flux = &rsm_flux[t * 4];
    v[0] = pos[0];
    v[1] = pos[1];
    v[2] = pos[2];
    v[3] = nrm[0];
    v[4] = nrm[2] < 0.0f ? -flux[0] * scale - 1e-30f : flux[0] * scale;
    v[5] = flux[1] * scale;
    v[6] = flux[2] * scale;
    v[7] = nrm[1];
  }
  const auto& g = gl();
  g.BindBuffer(GL_UNIFORM_BUFFER, vpl_buffer);
  g.BufferData(GL_UNIFORM_BUFFER, GLsizeiptr(vpl_scratch.size() * sizeof(float)), vpl_scratch.data(), GL_STREAM_DRAW);
  g.UseProgram(shade_program);
  g.Uniform1i(g.GetUniformLocation(shade_program, "u_vpl_count"), count);
}

Renderer::Impl::View Renderer::Impl::make_view(const FrameInput& in, int w, int h, glm::vec2 jitter) const {
  View v;
  const CameraState& cam = in.current->camera;
  v.view = cam.view;
  v.proj = camera_projection(cam, w, h);
  v.proj_jittered = jitter_projection(v.proj, jitter, w, h);
  const CameraState& pcam = in.previous ? in.previous->camera : cam;
  v.prev_vp = camera_projection(pcam, w, h) * pcam.view;
  v.prev_view = pcam.view;
  v.camera_pos = glm::vec3(glm::inverse(cam.view)[3]);
  v.znear = cam.znear > 0.0f ? cam.znear : 0.01f;
  v.zfar = cam.zfar > v.znear ? cam.zfar : 1000.0f * v.znear;
  return v;
}

void Renderer::Impl::draw_gbuffer(const Fbo& target, const View& v, float lod_bias) {
  const auto& g = gl();
  g.BindFramebuffer(GL_FRAMEBUFFER, target.fbo);
  g.Viewport(0, 0, target.width, target.height);
  const float zero[4] = {0, 0, 0, 0};
  const GLuint zero_u[4] = {0, 0, 0, 0};
  const float one = 1.0f;
  for (int i = 0; i < kId; ++i) g.ClearBufferfv(GL_COLOR, i, zero);
  g.ClearBufferuiv(GL_COLOR, kId, zero_u);
  g.ClearBufferfv(GL_DEPTH, 0, &one);
  g.Enable(GL_DEPTH_TEST);
  g.DepthFunc(GL_LESS);
  g.DepthMask(GL_TRUE);
  const GLuint prog = gbuffer_program;
  g.UseProgram(prog);
  const glm::mat4 vp = v.proj_jittered * v.view;
  const glm::mat4 cur_vp = v.proj * v.view;
  g.UniformMatrix4fv(g.GetUniformLocation(prog, "u_view_proj"), 1, GL_FALSE, glm::value_ptr(vp));
  g.UniformMatrix4fv(g.GetUniformLocation(prog, "u_cur_vp"), 1, GL_FALSE, glm::value_ptr(cur_vp));
  g.UniformMatrix4fv(g.GetUniformLocation(prog, "u_prev_vp"), 1, GL_FALSE, glm::value_ptr(v.prev_vp));
  g.UniformMatrix4fv(g.GetUniformLocation(prog, "u_view"), 1, GL_FALSE, glm::value_ptr(v.view));
  g.UniformMatrix4fv(g.GetUniformLocation(prog, "u_prev_view"), 1, GL_FALSE, glm::value_ptr(v.prev_view));
  g.Uniform2f(g.GetUniformLocation(prog, "u_size"), float(target.width), float(target.height));
  g.Uniform1f(g.GetUniformLocation(prog, "u_lod_bias"), lod_bias);
  gpu->draw_all(prog, true);
  g.Disable(GL_DEPTH_TEST);
}

void Renderer::Impl::shade(const Fbo& gb, const Fbo& target, const View& v, std::uint32_t seed, bool accumulate,
                           bool clear) {
  const auto& g = gl();
  const PayloadOptions& p = options.payload;
  g.BindFramebuffer(GL_FRAMEBUFFER, target.fbo);
  g.Viewport(0, 0, target.width, target.height);
  if (clear) {
    const float zero[4] = {0, 0, 0, 0};
    for (int i = 0; i < 3; ++i) g.ClearBufferfv(GL_COLOR, i, zero);
  }
  if (accumulate) {
    // Reference samples add up in float targets; the average is taken on read-back.
    g.Enable(GL_BLEND);
    g.BlendFunc(GL_ONE, GL_ONE);
  }
  const GLuint prog = shade_program;
  g.UseProgram(prog);
  for (int i = 0; i < 3; ++i) {
    g.ActiveTexture(GLenum(GL_TEXTURE0 + i));
    g.BindTexture(GL_TEXTURE_2D, gb.colors[std::size_t(i == 2 ? kWorld : i)]);
  }
  g.ActiveTexture(GL_TEXTURE3);
  g.BindTexture(GL_TEXTURE_2D, shadow_map.depth);
  g.ActiveTexture(GL_TEXTURE0);
  g.BindBufferBase(GL_UNIFORM_BUFFER, 0, vpl_buffer);
  const glm::mat4 bias = glm::translate(glm::mat4(1.0f), glm::vec3(0.5f)) * glm::scale(glm::mat4(1.0f), glm::vec3(0.5f));
  const glm::mat4 light_vp = bias * light.view_proj;
  set_lights(prog);
  g.Uniform3f(g.GetUniformLocation(prog, "u_camera_pos"), v.camera_pos.x, v.camera_pos.y, v.camera_pos.z);
  g.UniformMatrix4fv(g.GetUniformLocation(prog, "u_light_vp"), 1, GL_FALSE, glm::value_ptr(light_vp));
  g.Uniform1i(g.GetUniformLocation(prog, "u_pcf"), p.pcf_kernel);
  g.Uniform1f(g.GetUniformLocation(prog, "u_shadow_texel"), 1.0f / float(p.shadow_map_size));
  g.Uniform1f(g.GetUniformLocation(prog, "u_normal_offset"), p.shadow_bias * light.texel_world);
  g.Uniform1i(g.GetUniformLocation(prog, "u_ao_dirs"), p.ssao_directions);
  g.Uniform1i(g.GetUniformLocation(prog, "u_ao_steps"), p.ssao_steps);
  g.Uniform1f(g.GetUniformLocation(prog, "u_ao_radius"), p.ssao_radius > 0 ? p.ssao_radius : 0.05f * scene_diagonal);
  g.Uniform1f(g.GetUniformLocation(prog, "u_proj_scale"), v.proj[1][1] * 0.5f * float(target.height));
  g.Uniform1ui(g.GetUniformLocation(prog, "u_seed"), seed);
  const float clamp_d = p.vpl_clamp > 0 ? p.vpl_clamp : 0.02f * scene_diagonal;
  g.Uniform1f(g.GetUniformLocation(prog, "u_vpl_clamp2"), clamp_d * clamp_d);
  if (scene.ambient != glm::vec3(0.0f) || rig) {
    // Both ambients are radiances L (the scene's DomeLight, the rig's A): gi adds a(1-m)/pi * u_ambient, so
    // pi L makes a Lambertian surface reflect a(1-m) L, the integral of a/pi L (n.w) over the hemisphere (docs/usd.md).
    const glm::vec3 a = 3.14159265f * (state->ambient + glm::vec3(rig ? options.lighting.ambient : 0.0f));
    g.Uniform3f(g.GetUniformLocation(prog, "u_ambient"), a.x, a.y, a.z);
  }
  if (rig) {
    const float e = 3.14159265f * options.lighting.fill;
    const glm::vec3 d = scene.fill_direction;
    g.Uniform3f(g.GetUniformLocation(prog, "u_fill_irradiance"), e, e, e);
    g.Uniform3f(g.GetUniformLocation(prog, "u_fill_direction"), d.x, d.y, d.z);
  }
  g.BindVertexArray(empty_vao);
  g.DrawArrays(GL_TRIANGLES, 0, 3);
  g.BindVertexArray(0);
  g.Disable(GL_BLEND);
}

void Renderer::Impl::read_rgba(const Fbo& f, int attachment, int components) {
  const auto& g = gl();
  readback.resize(std::size_t(f.width) * std::size_t(f.height) * std::size_t(components));
  g.BindFramebuffer(GL_FRAMEBUFFER, f.fbo);
  g.ReadBuffer(GLenum(GL_COLOR_ATTACHMENT0 + attachment));
  g.PixelStorei(GL_PACK_ALIGNMENT, 4);
  g.ReadPixels(0, 0, f.width, f.height, components == 4 ? GL_RGBA : GL_RG, GL_FLOAT, readback.data());
}

void Renderer::Impl::read_uint(const Fbo& f, int attachment) {
  const auto& g = gl();
  readback_u.resize(std::size_t(f.width) * std::size_t(f.height));
  g.BindFramebuffer(GL_FRAMEBUFFER, f.fbo);
  g.ReadBuffer(GLenum(GL_COLOR_ATTACHMENT0 + attachment));
  g.PixelStorei(GL_PACK_ALIGNMENT, 4);
  g.ReadPixels(0, 0, f.width, f.height, GL_RED_INTEGER, GL_UNSIGNED_INT, readback_u.data());
}

namespace {
// Copies components of an interleaved GL read-back into planes, flipping rows: GL's row 0 is the bottom,
// the image's (and EXR's) row 0 is the top.
void scatter(const std::vector<float>& src, int w, int h, int components,
             std::initializer_list<std::pair<int, float*>> planes, float scale = 1.0f) {
  parallel_rows(h, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y) {
      const float* row = src.data() + std::size_t(h - 1 - y) * std::size_t(w) * std::size_t(components);
      for (auto [c, plane] : planes) {
        float* out = plane + std::size_t(y) * std::size_t(w);
        for (int x = 0; x < w; ++x) out[x] = row[std::size_t(x) * std::size_t(components) + std::size_t(c)] * scale;
      }
    }
  });
}
}  // namespace

Image Renderer::Impl::gbuffer_image(const Fbo& f, const View& v, const FrameInput& in) {
  const int w = f.width, h = f.height;
  Image img(w, h);
  float* depth = img.add_channel("depth.Z");
  float* nx = img.add_channel("N.X");
  float* ny = img.add_channel("N.Y");
  float* nz = img.add_channel("N.Z");
  float* mx = img.add_channel("motion.X");
  float* my = img.add_channel("motion.Y");
  float* prev_depth = img.add_channel("prevDepth.Z");
  std::uint32_t* id = img.add_uint_channel("id");
  float* ar = img.add_channel("albedo.R");
  float* ag = img.add_channel("albedo.G");
  float* ab = img.add_channel("albedo.B");
  read_rgba(f, kAlbedo, 4);
  scatter(readback, w, h, 4, {{0, ar}, {1, ag}, {2, ab}});
  read_rgba(f, kNormal, 4);
  scatter(readback, w, h, 4, {{0, nx}, {1, ny}, {2, nz}});
  read_rgba(f, kWorld, 4);
  scatter(readback, w, h, 4, {{3, depth}});
  read_rgba(f, kMotion, 4);
  scatter(readback, w, h, 4, {{0, mx}, {1, my}, {2, prev_depth}});
  read_uint(f, kId);
  for (int y = 0; y < h; ++y)
    std::copy_n(readback_u.data() + std::size_t(h - 1 - y) * std::size_t(w), w, id + std::size_t(y) * std::size_t(w));

  // Background: depth = prevDepth = clipFar and the camera-only motion of a point on the far plane.
  const glm::mat4 inv_vp = glm::inverse(v.proj * v.view);
  const bool moving = in.previous != nullptr && v.prev_vp != v.proj * v.view;
  parallel_rows(h, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < w; ++x) {
        const std::size_t i = std::size_t(y) * std::size_t(w) + std::size_t(x);
        if (id[i] != 0) continue;
        depth[i] = v.zfar;
        prev_depth[i] = v.zfar;
        if (!moving) continue;
        const float px = float(x) + 0.5f, py = float(y) + 0.5f;
        const glm::vec4 ndc(2.0f * px / float(w) - 1.0f, 1.0f - 2.0f * py / float(h), 1.0f, 1.0f);
        glm::vec4 world = inv_vp * ndc;
        world /= world.w;
        const glm::vec4 prev = v.prev_vp * world;
        if (prev.w <= 0.0f) continue;  // behind the previous camera: no meaningful position, keep 0
        const float qx = (prev.x / prev.w * 0.5f + 0.5f) * float(w);
        const float qy = (0.5f - prev.y / prev.w * 0.5f) * float(h);
        mx[i] = qx - px;
        my[i] = qy - py;
      }
  });
  return img;
}

Image Renderer::Impl::shade_image(const Fbo& f, float scale, double* dark) {
  const PayloadOptions& p = options.payload;
  const int w = f.width, h = f.height;
  Image img(w, h);
  float* r = img.add_channel("R");
  float* gch = img.add_channel("G");
  float* b = img.add_channel("B");
  read_rgba(f, 2, 4);
  scatter(readback, w, h, 4, {{0, r}, {1, gch}, {2, b}}, scale);
  if (dark) {
    // Covered pixels: the sum's alpha (1 per covered sample, shaders.cpp). Rec. 709 luminance of R,G,B.
    const std::size_t n = std::size_t(w) * std::size_t(h);
    auto luminance = [&](std::size_t i) {
      return 0.2126f * readback[4 * i] + 0.7152f * readback[4 * i + 1] + 0.0722f * readback[4 * i + 2];
    };
    float most = 0.0f;
    std::size_t covered = 0, below = 0;
    for (std::size_t i = 0; i < n; ++i)
      if (readback[4 * i + 3] > 0.0f) most = std::max(most, luminance(i));
    // A maximum below 1e-20 is a black frame up to rounding (products with a zero light leave values of 1e-33):
    // every covered pixel counts as dark.
    const bool black = !(most >= 1e-20f);
    for (std::size_t i = 0; i < n; ++i)
      if (readback[4 * i + 3] > 0.0f) {
        ++covered;
        below += black || !(luminance(i) >= 0.01f * most);
      }
    *dark = covered ? double(below) / double(covered) : 0.0;
  }
  if (p.direct || p.shadow) {
    read_rgba(f, 0, 4);
    if (p.direct)
      scatter(readback, w, h, 4,
              {{0, img.add_channel("direct.R")}, {1, img.add_channel("direct.G")}, {2, img.add_channel("direct.B")}}, scale);
    if (p.shadow) scatter(readback, w, h, 4, {{3, img.add_channel("shadow.Y")}}, scale);
  }
  if (p.gi || p.ssao) {
    read_rgba(f, 1, 4);
    if (p.gi)
      scatter(readback, w, h, 4, {{0, img.add_channel("gi.R")}, {1, img.add_channel("gi.G")}, {2, img.add_channel("gi.B")}},
              scale);
    if (p.ssao) scatter(readback, w, h, 4, {{3, img.add_channel("ssao.Y")}}, scale);
  }
  return img;
}

void Renderer::Impl::set_metadata(Image& image, const FrameInput& in, const View& v, glm::vec2 jitter) const {
  FrameMetadata& m = image.metadata();
  m.world_to_camera = v.view;
  m.world_to_ndc = v.proj_jittered * v.view;
  m.near_clip = v.znear;
  m.far_clip = v.zfar;
  m.frame = in.frame;
  m.fps = in.fps;
  m.time = double(in.frame) / in.fps;
  m.jitter = jitter;
  m.camera_cut = in.camera_cut;
  // Which context made the image (issue 22): outputs of different devices may differ (docs/render-gbuffer.md).
  const GlInfo& info = context->info();
  m.extra["glContext"] = info.context;
  if (info.device >= 0) m.extra["glDevice"] = std::to_string(info.device);
  m.extra["glVendor"] = info.vendor;
  m.extra["glRenderer"] = info.renderer;
  m.extra["glVersion"] = info.version;
}

// ---- Renderer --------------------------------------------------------------------------------------------

Renderer::Renderer() : impl_(std::make_unique<Impl>()) {}
Renderer::Renderer(Renderer&&) noexcept = default;
Renderer& Renderer::operator=(Renderer&&) noexcept = default;
Renderer::~Renderer() = default;

const RenderOptions& Renderer::options() const { return impl_->options; }
std::string Renderer::gl_description() const { return impl_->context->description(); }
const GlInfo& Renderer::gl_info() const { return impl_->context->info(); }
bool Renderer::has_gpu_timer() const { return impl_->timer; }

Expected<Renderer> Renderer::create(const RenderOptions& options, const SceneGeometry& scene) {
  if (auto s = validate(options); !s) return s.error();
  if (!scene.primitives || !scene.materials || !scene.textures) return Error::internal("Renderer::create without a scene");

  Renderer r;
  Impl& impl = *r.impl_;
  impl.options = options;
  impl.scene = scene;
  auto ctx = create_context(options.gl, options.gl_device);
  if (!ctx) return ctx.error();
  impl.context = std::move(*ctx);
  if (auto s = impl.init(); !s) return s.error();
  return r;
}

// One pass of Renderer::render each: they render, time (wall clock after glFinish, GL_TIME_ELAPSED where the
// context has it) and convert their targets into `result`'s images.
Status Renderer::Impl::pass_light_maps(const FrameInput& in, RenderedFrame& result) {
  const auto t0 = Clock::now();
  timer_begin(0);
  if (auto s = light_maps(*in.current); !s) return s;
  timer_end();
  select_vpls(instant_key(in.frame, in.fps), 0);
  gl().Finish();
  result.timings_ms[kPassLightMaps] = ms_since(t0);
  if (timer) result.gpu_ms[kPassLightMaps] = timer_ms(0);
  return Status::ok();
}

void Renderer::Impl::pass_gbuffer(const FrameInput& in, const View& full, RenderedFrame& result) {
  const auto t0 = Clock::now();
  timer_begin(0);
  draw_gbuffer(gbuffer_full, full);
  timer_end();
  gl().Finish();
  result.timings_ms[kPassGbuffer] = ms_since(t0);
  if (timer) result.gpu_ms[kPassGbuffer] = timer_ms(0);
  result.gbuffer = gbuffer_image(gbuffer_full, full, in);
  set_metadata(*result.gbuffer, in, full, {0.0f, 0.0f});
  result.gbuffer->metadata().compute_ms = result.timings_ms[kPassGbuffer];
}

// The low-resolution payload: a G-buffer rendered at 1/k with this frame's jitter (in low-res pixels, conventions
// "Jitter"), shaded directly. Its samples are exactly full-res pixel centres for the regular pattern. Textures are
// read at the full-resolution mip level (LOD bias -log2 k by default, RenderOptions).
void Renderer::Impl::pass_shade_low(const FrameInput& in, std::uint32_t instant, std::uint32_t frame_seed,
                                    RenderedFrame& result) {
  const RenderOptions& o = options;
  const int k = o.factor;
  const glm::vec2 jitter = frame_jitter(o.shade_jitter, jitter_frame(o.shade_jitter, in.frame, instant), k, o.seed);
  const View low = make_view(in, o.width / k, o.height / k, jitter);
  const float lod_bias = o.shade_mip_bias ? *o.shade_mip_bias : -std::log2(float(k));
  const auto t0 = Clock::now();
  timer_begin(0);
  draw_gbuffer(gbuffer_low, low, lod_bias);
  shade(gbuffer_low, shade_low, low, frame_seed, false, true);
  timer_end();
  gl().Finish();
  result.timings_ms[kPassShadeLow] = ms_since(t0);
  if (timer) result.gpu_ms[kPassShadeLow] = timer_ms(0);
  result.shade = shade_image(shade_low, 1.0f, &result.dark_fraction);
  set_metadata(*result.shade, in, low, jitter);
  result.shade->metadata().jitter_factor = k;
  if (o.shade_jitter == JitterMode::Regular) result.shade->metadata().jitter_index = regular_jitter_index(in.frame, k);
  result.shade->metadata().compute_ms = result.timings_ms[kPassShadeLow];
}

// Colour: the same payload at full resolution, one sample per pixel at the colour jitter (no AA).
void Renderer::Impl::pass_color(const FrameInput& in, std::uint32_t instant, std::uint32_t frame_seed,
                                RenderedFrame& result) {
  const RenderOptions& o = options;
  const int w = o.width, h = o.height;
  const glm::vec2 jitter =
      frame_jitter(o.color_jitter, jitter_frame(o.color_jitter, in.frame, instant), o.factor, o.seed ^ 0xc0104u);
  const View view = make_view(in, w, h, jitter);
  const auto t0 = Clock::now();
  timer_begin(0);
  draw_gbuffer(gbuffer_full, view);
  timer_end();
  gl().Finish();
  const auto t1 = Clock::now();
  timer_begin(1);
  shade(gbuffer_full, shade_full, view, frame_seed, false, true);
  timer_end();
  gl().Finish();
  result.timings_ms[kPassShadeFull] = ms_since(t1);
  result.timings_ms[kPassColor] = ms_since(t0);
  if (timer) {
    result.gpu_ms[kPassShadeFull] = timer_ms(1);
    result.gpu_ms[kPassColor] = timer_ms(0) + timer_ms(1);
  }
  Image full_payload = shade_image(shade_full, 1.0f, &result.dark_fraction);
  Image color(w, h);
  for (const char* c : {"R", "G", "B"}) std::copy_n(full_payload.plane(c), full_payload.pixel_count(), color.add_channel(c));
  result.color = std::move(color);
  set_metadata(*result.color, in, view, jitter);
  result.color->metadata().compute_ms = result.timings_ms[kPassColor];
}

// Reference: reference_spp full-resolution samples at Halton (2,3) sub-pixel positions (or all at the pixel centres
// with reference_jitter = None), each with its own SSAO pattern and VPL set, accumulated in float targets and
// averaged.
void Renderer::Impl::pass_reference(const FrameInput& in, const View& full, std::uint32_t instant,
                                    RenderedFrame& result) {
  const RenderOptions& o = options;
  const auto t0 = Clock::now();
  timer_begin(0);
  const bool centred = o.reference_jitter == JitterMode::None;
  for (int s = 0; s < o.reference_spp; ++s) {
    const auto i = std::uint32_t(s + 1);
    const glm::vec2 jitter =
        centred ? glm::vec2(0.0f) : glm::vec2(radical_inverse(i, 2) - 0.5f, radical_inverse(i, 3) - 0.5f);
    const View view = make_view(in, o.width, o.height, jitter);
    if (s > 0 && rsm.fbo) select_vpls(instant, s);
    draw_gbuffer(gbuffer_full, view);
    shade(gbuffer_full, shade_full, view, hash_u32(o.seed, instant, 0xbeefu, i), true, s == 0);
  }
  timer_end();
  gl().Finish();
  result.timings_ms[kPassReference] = ms_since(t0);
  if (timer) result.gpu_ms[kPassReference] = timer_ms(0);
  double dark = -1.0;
  result.reference = shade_image(shade_full, 1.0f / float(o.reference_spp), &dark);
  if (!o.outputs.color) result.dark_fraction = dark;  // the colour image's count wins
  set_metadata(*result.reference, in, full, {0.0f, 0.0f});
  result.reference->metadata().compute_ms = result.timings_ms[kPassReference];
}

// Warns once, at the first frame that is mostly black.
void Renderer::Impl::warn_if_dark(const FrameInput& in, double dark_fraction) {
  if (dark_fraction <= 0.5 || dark_warned || !options.warning) return;
  dark_warned = true;
  const int percent = int(std::lround(100.0 * dark_fraction));
  options.warning("frame " + std::to_string(in.frame) + ": " + std::to_string(percent) +
                  " % of the covered pixels are below 1 % of the frame's maximum: the render is mostly black and "
                  "flatters every metric (raise --key-light, --fill-light or --ambient, or --lights auto; later dark "
                  "frames are not reported)");
}

Expected<RenderedFrame> Renderer::render(const FrameInput& in) {
  Impl& im = *impl_;
  if (!in.current) return Error::internal("Renderer::render without a frame state");
  im.context->make_current();
  const auto& g = im.gl();
  const RenderOptions& o = im.options;
  const RenderOutputs& out = o.outputs;
  RenderedFrame result;

  if (auto s = im.gpu->prepare(*in.current, in.previous); !s) return s.error();
  im.state = in.current;
  g.Finish();

  const bool payload = out.shade || out.reference || out.color;
  if (payload && (o.payload.shadow || o.payload.gi))
    if (Status s = im.pass_light_maps(in, result); !s) return s.error();
  // Random patterns (SSAO rotations, VPL sets, random jitter) are keyed by the frame's instant, not its number, so
  // a 40 Hz frame n and a 120 Hz frame 3n are the same render (docs/conventions.md, "Jitter" and "Noise").
  const std::uint32_t instant = instant_key(in.frame, in.fps);
  const std::uint32_t frame_seed = hash_u32(o.seed, instant, 0xa0u);
  const Impl::View full = im.make_view(in, o.width, o.height, {0.0f, 0.0f});
  if (out.gbuffer) im.pass_gbuffer(in, full, result);
  if (out.shade) im.pass_shade_low(in, instant, frame_seed, result);
  if (out.color) im.pass_color(in, instant, frame_seed, result);
  if (out.reference) im.pass_reference(in, full, instant, result);
  if (auto s = check_gl(g, "frame"); !s) return s.error();
  for (Image* img : {result.gbuffer ? &*result.gbuffer : nullptr, result.shade ? &*result.shade : nullptr,
                     result.color ? &*result.color : nullptr, result.reference ? &*result.reference : nullptr})
    if (img) img->metadata().timings_ms = result.timings_ms;
  im.warn_if_dark(in, result.dark_fraction);
  return result;
}

}  // namespace temporal
