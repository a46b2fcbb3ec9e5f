// EGL's device platform and surfaceless contexts (temporal/gpu/egl.h), through a libEGL.so.1 opened at run time.
#include "temporal/gpu/egl.h"

#define EGL_NO_PROTOTYPES
#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <dlfcn.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <type_traits>

namespace temporal::gpu::egl {
namespace {

// The EGL 1.5 entry points used here, and the device-platform extensions (loaded by name: glvnd exports only EGL
// 1.5's core).
struct Egl {
  PFNEGLGETPROCADDRESSPROC GetProcAddress = nullptr;
  PFNEGLQUERYSTRINGPROC QueryString = nullptr;
  PFNEGLINITIALIZEPROC Initialize = nullptr;
  PFNEGLBINDAPIPROC BindAPI = nullptr;
  PFNEGLCHOOSECONFIGPROC ChooseConfig = nullptr;
  PFNEGLCREATECONTEXTPROC CreateContext = nullptr;
  PFNEGLDESTROYCONTEXTPROC DestroyContext = nullptr;
  PFNEGLMAKECURRENTPROC MakeCurrent = nullptr;
  PFNEGLGETCURRENTCONTEXTPROC GetCurrentContext = nullptr;
  PFNEGLGETERRORPROC GetError = nullptr;
  PFNEGLQUERYDEVICESEXTPROC QueryDevices = nullptr;
  PFNEGLQUERYDEVICESTRINGEXTPROC QueryDeviceString = nullptr;
  PFNEGLGETPLATFORMDISPLAYEXTPROC GetPlatformDisplay = nullptr;
  std::string error;  // why loading failed; empty when loaded
};

// Loaded once per process (the handle is never closed: contexts may live until exit).
const Egl& api() {
  static const Egl loaded = [] {
    Egl e;
    void* lib = dlopen("libEGL.so.1", RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
      const char* why = dlerror();
      e.error = std::string("cannot load libEGL.so.1 (") + (why ? why : "?") +
                "): install libegl1 and a driver (libegl-mesa0 for llvmpipe)";
      return e;
    }
    auto load = [&](auto& fn, const char* name) {
      fn = reinterpret_cast<std::remove_reference_t<decltype(fn)>>(dlsym(lib, name));
      if (!fn && e.error.empty()) e.error = std::string("libEGL.so.1 has no ") + name;
    };
    load(e.GetProcAddress, "eglGetProcAddress");
    load(e.QueryString, "eglQueryString");
    load(e.Initialize, "eglInitialize");
    load(e.BindAPI, "eglBindAPI");
    load(e.ChooseConfig, "eglChooseConfig");
    load(e.CreateContext, "eglCreateContext");
    load(e.DestroyContext, "eglDestroyContext");
    load(e.MakeCurrent, "eglMakeCurrent");
    load(e.GetCurrentContext, "eglGetCurrentContext");
    load(e.GetError, "eglGetError");
    if (!e.error.empty()) return e;
    const char* client = e.QueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (!client) {
      e.error = "EGL has no client extensions (is a vendor library, e.g. libegl-mesa0 or a GPU driver, installed?)";
      return e;
    }
    if (!has_extension(client, "EGL_EXT_platform_device") ||
        !(has_extension(client, "EGL_EXT_device_enumeration") || has_extension(client, "EGL_EXT_device_base"))) {
      e.error = std::string("EGL lacks the device platform (EGL_EXT_platform_device, EGL_EXT_device_enumeration); "
                            "its client extensions: ") + client;
      return e;
    }
    e.QueryDevices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(e.GetProcAddress("eglQueryDevicesEXT"));
    e.QueryDeviceString = reinterpret_cast<PFNEGLQUERYDEVICESTRINGEXTPROC>(e.GetProcAddress("eglQueryDeviceStringEXT"));
    e.GetPlatformDisplay = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(e.GetProcAddress("eglGetPlatformDisplayEXT"));
    if (!e.QueryDevices || !e.GetPlatformDisplay)
      e.error = "EGL advertises the device platform but lacks eglQueryDevicesEXT or eglGetPlatformDisplayEXT";
    return e;
  }();
  return loaded;
}

// "STEP failed (EGL error 0x3001)"
Error step_failed(const std::string& step) {
  char code[16];
  std::snprintf(code, sizeof code, "0x%04x", unsigned(api().GetError()));
  return Error::internal(step + " failed (EGL error " + code + ")");
}

// The device handles, in eglQueryDevicesEXT's order.
Expected<std::vector<EGLDeviceEXT>> device_handles() {
  const Egl& e = api();
  if (!e.error.empty()) return Error::usage(e.error);
  EGLint n = 0;
  if (!e.QueryDevices(0, nullptr, &n)) return step_failed("eglQueryDevicesEXT");
  std::vector<EGLDeviceEXT> handles(std::size_t(std::max(n, 0)));
  if (n > 0 && !e.QueryDevices(n, handles.data(), &n)) return step_failed("eglQueryDevicesEXT");
  handles.resize(std::size_t(std::max(n, 0)));
  return handles;
}

}  // namespace

bool has_extension(const char* list, const char* word) {
  if (!list) return false;
  const std::size_t n = std::strlen(word);
  for (const char* p = std::strstr(list, word); p; p = std::strstr(p + 1, word))
    if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return true;
  return false;
}

Expected<std::vector<Device>> devices() {
  auto handles = device_handles();
  if (!handles) return handles.error();
  std::vector<Device> out;
  for (std::size_t i = 0; i < handles->size(); ++i) {
    Device d;
    d.index = int(i);
    const char* s = api().QueryDeviceString ? api().QueryDeviceString((*handles)[i], EGL_EXTENSIONS) : nullptr;
    d.extensions = s ? s : "";
    d.software = has_extension(d.extensions.c_str(), "EGL_MESA_device_software");
    out.push_back(std::move(d));
  }
  return out;
}

int default_device(const std::vector<Device>& devices) {
  for (const Device& d : devices)
    if (!d.software) return d.index;
  return devices.empty() ? -1 : 0;
}

void* SurfacelessContext::proc_address(const char* name) {
  const Egl& e = api();
  return e.GetProcAddress ? reinterpret_cast<void*>(e.GetProcAddress(name)) : nullptr;
}

Expected<std::unique_ptr<SurfacelessContext>> SurfacelessContext::create(int index) {
  auto handles = device_handles();
  if (!handles) return handles.error();
  if (index < 0 || index >= int(handles->size()))
    return Error::usage("EGL device " + std::to_string(index) + " does not exist: EGL lists " +
                        std::to_string(handles->size()) + " device(s)");
  const Egl& e = api();
  const std::string device = "EGL device " + std::to_string(index);
  EGLDisplay display = e.GetPlatformDisplay(EGL_PLATFORM_DEVICE_EXT, (*handles)[std::size_t(index)], nullptr);
  if (display == EGL_NO_DISPLAY) return step_failed("eglGetPlatformDisplayEXT (" + device + ")");
  EGLint major = 0, minor = 0;
  if (!e.Initialize(display, &major, &minor)) return step_failed("eglInitialize (" + device + ")");
  const char* ext = e.QueryString(display, EGL_EXTENSIONS);
  if (!has_extension(ext, "EGL_KHR_surfaceless_context"))
    return Error::internal(device + " lacks EGL_KHR_surfaceless_context");
  if (!e.BindAPI(EGL_OPENGL_API)) return step_failed("eglBindAPI(EGL_OPENGL_API)");
  EGLConfig config = EGL_NO_CONFIG_KHR;
  if (!has_extension(ext, "EGL_KHR_no_config_context")) {
    // Without no-config contexts, any config that renders desktop OpenGL will do: it only describes a default
    // framebuffer that is never used.
    const EGLint want[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_SURFACE_TYPE, 0, EGL_NONE};
    EGLint n = 0;
    if (!e.ChooseConfig(display, want, &config, 1, &n) || n < 1)
      return Error::internal(device + " has no config for desktop OpenGL");
  }
  // Core profile 4.5: the shaders and kernels are #version 450 core, and 4.5 is the highest llvmpipe grants.
  const EGLint attribs[] = {EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 5,
                            EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
  EGLContext context = e.CreateContext(display, config, EGL_NO_CONTEXT, attribs);
  if (context == EGL_NO_CONTEXT) return step_failed("eglCreateContext (OpenGL 4.5 core, " + device + ")");
  std::unique_ptr<SurfacelessContext> ctx(new SurfacelessContext());
  ctx->display_ = display;
  ctx->context_ = context;
  ctx->index_ = index;
  if (!e.MakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context)) return step_failed("eglMakeCurrent (surfaceless)");
  return ctx;
}

SurfacelessContext::~SurfacelessContext() {
  const Egl& e = api();
  if (!display_ || !context_) return;
  if (e.GetCurrentContext() == context_) e.MakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  e.DestroyContext(display_, context_);
}

bool SurfacelessContext::is_current() const { return api().GetCurrentContext() == context_; }

Status SurfacelessContext::make_current() const {
  if (!api().MakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_)) return step_failed("eglMakeCurrent");
  return Status::ok();
}

}  // namespace temporal::gpu::egl
