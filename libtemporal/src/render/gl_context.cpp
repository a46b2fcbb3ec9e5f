// The two ways the renderer gets an OpenGL 4.5 core context (gl_api.h): OSMesa, and EGL's device platform.
// EGL is the gpu stage's module (temporal/gpu/egl.h: device enumeration and the surfaceless context, shared with
// the compute kernels' context): glvnd's libEGL opened at run time, never libGL or libOpenGL, every GL entry point
// from eglGetProcAddress, so a machine with nothing but a GPU driver and glvnd's loader can run it
// (docs/render-gbuffer.md, "Rendering on a GPU").
#include "gl_api.h"

#include "temporal/gpu/egl.h"

#include <GL/osmesa.h>

namespace temporal::render_detail {

namespace {

// The context this thread last made current through make_current(), so that make_current() binds again exactly
// when another context took the thread (a second renderer; the tests keep an OSMesa and an EGL renderer side by
// side), and not on every frame. It matters for OSMesa: its entry points dispatch through Mesa's libglapi, whose
// current context eglMakeCurrent also sets (RenderEgl.OsmesaAndEglRenderersTakeTurnsOnOneThread fails without the
// re-bind). EGL's entry points dispatch through glvnd's own table and kept their context in that test even without
// it, but EGL promises nothing of the kind, so EGL re-binds too.
thread_local const GlContext* g_current = nullptr;

// ---- OSMesa -----------------------------------------------------------------------------------------------

class OsmesaContext final : public GlContext {
 public:
  ~OsmesaContext() override {
    if (g_current == this) g_current = nullptr;
    if (context_) OSMesaDestroyContext(context_);
  }
  void make_current() override {
    if (g_current == this) return;
    OSMesaMakeCurrent(context_, dummy_, GL_UNSIGNED_BYTE, 1, 1);
    g_current = this;
  }
  Status init() {
    // Core profile 4.5 is the highest llvmpipe grants (4.6 is refused, docs/building.md). No depth or
    // stencil in the default framebuffer: every pass renders into its own FBO.
    const int attribs[] = {OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 0, OSMESA_STENCIL_BITS, 0,
                           OSMESA_PROFILE, OSMESA_CORE_PROFILE, OSMESA_CONTEXT_MAJOR_VERSION, 4,
                           OSMESA_CONTEXT_MINOR_VERSION, 5, 0};
    context_ = OSMesaCreateContextAttribs(attribs, nullptr);
    if (!context_)
      return Error::internal("OSMesa could not create an OpenGL 4.5 core context (is Mesa's llvmpipe installed?)");
    if (!OSMesaMakeCurrent(context_, dummy_, GL_UNSIGNED_BYTE, 1, 1)) return Error::internal("OSMesaMakeCurrent failed");
    g_current = this;
    return load([](const char* name) { return reinterpret_cast<void*>(OSMesaGetProcAddress(name)); }, "osmesa", -1);
  }

 private:
  OSMesaContext context_ = nullptr;
  unsigned char dummy_[16] = {};  // 1x1 default framebuffer (all rendering goes to FBOs)
};

// ---- EGL ----------------------------------------------------------------------------------------------------

class EglContext final : public GlContext {
 public:
  ~EglContext() override {
    if (g_current == this) g_current = nullptr;
  }
  void make_current() override {
    if (g_current == this) return;
    (void)surfaceless_->make_current();  // fails only when the context is lost; the next GL call then reports it
    g_current = this;
  }
  Status init(int index) {
    auto made = gpu::egl::SurfacelessContext::create(index);
    if (!made) return Error::internal(made.error().message);
    surfaceless_ = std::move(*made);
    g_current = this;
    return load(&gpu::egl::SurfacelessContext::proc_address, "egl", index);
  }

 private:
  std::unique_ptr<gpu::egl::SurfacelessContext> surfaceless_;
};

Expected<std::unique_ptr<GlContext>> egl_context_on(int index) {
  auto ctx = std::make_unique<EglContext>();
  if (auto s = ctx->init(index); !s) return s.error();
  return std::unique_ptr<GlContext>(std::move(ctx));
}

}  // namespace

Expected<std::unique_ptr<GlContext>> create_osmesa_context() {
  auto ctx = std::make_unique<OsmesaContext>();
  if (auto s = ctx->init(); !s) return s.error();
  return std::unique_ptr<GlContext>(std::move(ctx));
}

Expected<std::unique_ptr<GlContext>> create_egl_context(int device) {
  auto d = gpu::egl::devices();
  if (!d) return Error::internal(d.error().message);
  if (d->empty()) return Error::internal("EGL finds no device (render-gbuffer --list-gl-devices)");
  const int index = device < 0 ? gpu::egl::default_device(*d) : device;
  if (index >= int(d->size()))
    return Error::usage("--gl-device " + std::to_string(device) + ": EGL has " + std::to_string(d->size()) +
                        " device(s), 0.." + std::to_string(d->size() - 1) + " (render-gbuffer --list-gl-devices)");
  return egl_context_on(index);
}

Expected<std::unique_ptr<GlContext>> create_context(GlApi api, int device) {
  switch (api) {
    case GlApi::OSMesa: return create_osmesa_context();
    case GlApi::Egl: return create_egl_context(device);
    case GlApi::Auto: break;
  }
  // Auto: a GPU when EGL has one (the asked-for device when --gl-device is given), else llvmpipe through OSMesa.
  // A missing or broken EGL is not an error here: OSMesa is the fallback the CI path uses anyway.
  if (auto d = gpu::egl::devices()) {
    const int index = device >= 0 ? device : gpu::egl::default_device(*d);
    if (index >= 0 && index < int(d->size()) && !(*d)[std::size_t(index)].software)
      if (auto ctx = egl_context_on(index)) return ctx;
  }
  return create_osmesa_context();
}

}  // namespace temporal::render_detail

namespace temporal {

Expected<std::vector<GlDevice>> list_gl_devices() {
  auto d = gpu::egl::devices();
  if (!d) return Error::internal(d.error().message);
  std::vector<GlDevice> out;
  for (const gpu::egl::Device& device : *d) {
    GlDevice dev;
    dev.index = device.index;
    dev.extensions = device.extensions;
    dev.software = device.software;
    auto ctx = render_detail::egl_context_on(device.index);
    if (ctx) {
      dev.renderer = (*ctx)->info().renderer;
      dev.version = (*ctx)->info().version;
    } else {
      dev.error = ctx.error().message;
    }
    out.push_back(std::move(dev));
  }
  return out;
}

Expected<GlApi> parse_gl_api(const std::string& name) {
  if (name == "osmesa") return GlApi::OSMesa;
  if (name == "egl") return GlApi::Egl;
  if (name == "auto") return GlApi::Auto;
  return Error::usage("--gl '" + name + "': use osmesa, egl or auto");
}

const char* to_string(GlApi api) {
  switch (api) {
    case GlApi::Egl: return "egl";
    case GlApi::Auto: return "auto";
    case GlApi::OSMesa: break;
  }
  return "osmesa";
}

}  // namespace temporal
