// The two ways the renderer gets an OpenGL 4.5 core context (gl_api.h): OSMesa, and EGL's device platform.
// EGL is reached only through glvnd's libEGL (never libGL or libOpenGL: every GL entry point comes from
// eglGetProcAddress, which EGL 1.5 defines for core functions too), so a machine with nothing but a GPU driver and
// glvnd's loader can run it (docs/render-gbuffer.md, "Rendering on a GPU").
#include "gl_api.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/osmesa.h>

#include <cstring>
#include <sstream>

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

// ---- EGL --------------------------------------------------------------------------------------------------

std::string egl_error(const char* what) {
  std::ostringstream s;
  s << what << " failed (EGL error 0x" << std::hex << eglGetError() << ")";
  return s.str();
}

bool has_word(const char* list, const char* word) {
  if (!list) return false;
  const std::size_t n = std::strlen(word);
  for (const char* p = std::strstr(list, word); p; p = std::strstr(p + 1, word))
    if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return true;
  return false;
}

// The device-platform entry points (extensions: loaded by name, as glvnd exports only EGL 1.5's core).
struct EglDevices {
  PFNEGLQUERYDEVICESEXTPROC query_devices = nullptr;
  PFNEGLQUERYDEVICESTRINGEXTPROC query_device_string = nullptr;
  PFNEGLGETPLATFORMDISPLAYEXTPROC get_platform_display = nullptr;
  std::vector<EGLDeviceEXT> devices;
};

Expected<EglDevices> egl_devices() {
  const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  if (!client)
    return Error::internal("EGL has no client extensions (is glvnd's libEGL with a vendor library, e.g. libegl-mesa0 "
                           "or a GPU driver, installed?)");
  if (!has_word(client, "EGL_EXT_platform_device") ||
      !(has_word(client, "EGL_EXT_device_enumeration") || has_word(client, "EGL_EXT_device_base")))
    return Error::internal(std::string("EGL lacks the device platform (EGL_EXT_platform_device, "
                                       "EGL_EXT_device_enumeration); its client extensions: ") + client);
  EglDevices d;
  d.query_devices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
  d.query_device_string = reinterpret_cast<PFNEGLQUERYDEVICESTRINGEXTPROC>(eglGetProcAddress("eglQueryDeviceStringEXT"));
  d.get_platform_display = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
  if (!d.query_devices || !d.get_platform_display)
    return Error::internal("EGL advertises the device platform but lacks eglQueryDevicesEXT or eglGetPlatformDisplayEXT");
  EGLint n = 0;
  if (!d.query_devices(0, nullptr, &n)) return Error::internal(egl_error("eglQueryDevicesEXT"));
  d.devices.resize(std::size_t(std::max(n, 0)));
  if (n > 0 && !d.query_devices(n, d.devices.data(), &n)) return Error::internal(egl_error("eglQueryDevicesEXT"));
  d.devices.resize(std::size_t(std::max(n, 0)));
  return d;
}

std::string device_extensions(const EglDevices& d, EGLDeviceEXT device) {
  const char* s = d.query_device_string ? d.query_device_string(device, EGL_EXTENSIONS) : nullptr;
  return s ? s : "";
}

bool is_software(const std::string& extensions) { return has_word(extensions.c_str(), "EGL_MESA_device_software"); }

// The first hardware device, else the first device; -1 when there is none.
int default_device(const EglDevices& d) {
  for (std::size_t i = 0; i < d.devices.size(); ++i)
    if (!is_software(device_extensions(d, d.devices[i]))) return int(i);
  return d.devices.empty() ? -1 : 0;
}

class EglContext final : public GlContext {
 public:
  ~EglContext() override {
    if (g_current == this) g_current = nullptr;
    if (context_ != EGL_NO_CONTEXT) {
      if (eglGetCurrentContext() == context_) eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
      eglDestroyContext(display_, context_);
    }
    // No eglTerminate: the display of a device is one per process, shared by every context made on it (another
    // renderer, --list-gl-devices); terminating it would destroy theirs.
  }
  void make_current() override {
    if (g_current == this) return;
    eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_);
    g_current = this;
  }
  Status init(const EglDevices& d, int index) {
    display_ = d.get_platform_display(EGL_PLATFORM_DEVICE_EXT, d.devices[std::size_t(index)], nullptr);
    if (display_ == EGL_NO_DISPLAY) return Error::internal(egl_error("eglGetPlatformDisplayEXT"));
    EGLint major = 0, minor = 0;
    if (!eglInitialize(display_, &major, &minor)) return Error::internal(egl_error("eglInitialize"));
    const char* ext = eglQueryString(display_, EGL_EXTENSIONS);
    // Surfaceless: no window and no pbuffer; every pass draws into FBOs.
    if (!has_word(ext, "EGL_KHR_surfaceless_context"))
      return Error::internal("EGL device " + std::to_string(index) + " lacks EGL_KHR_surfaceless_context");
    if (!eglBindAPI(EGL_OPENGL_API)) return Error::internal(egl_error("eglBindAPI(EGL_OPENGL_API)"));
    EGLConfig config = EGL_NO_CONFIG_KHR;
    if (!has_word(ext, "EGL_KHR_no_config_context")) {
      // Without no_config contexts, any config that renders desktop OpenGL will do: it only describes a default
      // framebuffer the renderer never uses.
      const EGLint want[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_SURFACE_TYPE, 0, EGL_NONE};
      EGLint n = 0;
      if (!eglChooseConfig(display_, want, &config, 1, &n) || n < 1)
        return Error::internal("EGL device " + std::to_string(index) + " has no config for desktop OpenGL");
    }
    // Core profile 4.5, as with OSMesa (the shaders are #version 450 core).
    const EGLint attribs[] = {EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 5,
                              EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
    context_ = eglCreateContext(display_, config, EGL_NO_CONTEXT, attribs);
    if (context_ == EGL_NO_CONTEXT)
      return Error::internal(egl_error(("an OpenGL 4.5 core context on EGL device " + std::to_string(index)).c_str()));
    if (!eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_))
      return Error::internal(egl_error("eglMakeCurrent (surfaceless)"));
    g_current = this;
    return load([](const char* name) { return reinterpret_cast<void*>(eglGetProcAddress(name)); }, "egl", index);
  }

 private:
  EGLDisplay display_ = EGL_NO_DISPLAY;
  EGLContext context_ = EGL_NO_CONTEXT;
};

Expected<std::unique_ptr<GlContext>> egl_context_on(const EglDevices& d, int index) {
  auto ctx = std::make_unique<EglContext>();
  if (auto s = ctx->init(d, index); !s) return s.error();
  return std::unique_ptr<GlContext>(std::move(ctx));
}

}  // namespace

Expected<std::unique_ptr<GlContext>> create_osmesa_context() {
  auto ctx = std::make_unique<OsmesaContext>();
  if (auto s = ctx->init(); !s) return s.error();
  return std::unique_ptr<GlContext>(std::move(ctx));
}

Expected<std::unique_ptr<GlContext>> create_egl_context(int device) {
  auto d = egl_devices();
  if (!d) return d.error();
  if (d->devices.empty()) return Error::internal("EGL finds no device (render-gbuffer --list-gl-devices)");
  const int index = device < 0 ? default_device(*d) : device;
  if (index >= int(d->devices.size()))
    return Error::usage("--gl-device " + std::to_string(device) + ": EGL has " + std::to_string(d->devices.size()) +
                        " device(s), 0.." + std::to_string(d->devices.size() - 1) + " (render-gbuffer --list-gl-devices)");
  return egl_context_on(*d, index);
}

Expected<std::unique_ptr<GlContext>> create_context(GlApi api, int device) {
  switch (api) {
    case GlApi::OSMesa: return create_osmesa_context();
    case GlApi::Egl: return create_egl_context(device);
    case GlApi::Auto: break;
  }
  // Auto: a GPU when EGL has one (the asked-for device when --gl-device is given), else llvmpipe through OSMesa.
  // A missing or broken EGL is not an error here: OSMesa is the fallback the CI path uses anyway.
  if (auto d = egl_devices()) {
    const int index = device >= 0 ? device : default_device(*d);
    if (index >= 0 && index < int(d->devices.size()) && !is_software(device_extensions(*d, d->devices[std::size_t(index)])))
      if (auto ctx = egl_context_on(*d, index)) return ctx;
  }
  return create_osmesa_context();
}

}  // namespace temporal::render_detail

namespace temporal {

Expected<std::vector<GlDevice>> list_gl_devices() {
  using namespace render_detail;
  auto d = egl_devices();
  if (!d) return d.error();
  std::vector<GlDevice> out;
  for (std::size_t i = 0; i < d->devices.size(); ++i) {
    GlDevice dev;
    dev.index = int(i);
    dev.extensions = device_extensions(*d, d->devices[i]);
    dev.software = is_software(dev.extensions);
    auto ctx = egl_context_on(*d, int(i));
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
