// EGL's device platform: the one place the suite enumerates EGL devices and makes a surfaceless OpenGL 4.5 core
// context on one (the recipe of shared/tools/egl-probe.c, verified on llvmpipe and on an NVIDIA H200 driver-only
// machine). Both users build on it: the gpu stage's compute context (temporal/gpu/context.h) and the renderer's
// EGL context (render/gl_context.cpp, `render-gbuffer --gl egl`).
//
// libEGL.so.1 (glvnd's dispatcher, or a vendor's libEGL) is opened at run time on the first call, not linked: a
// program that never asks for EGL never loads it, the method stages' CPU kernel benchmarks link no display
// library (kernel_dependencies.*), and a machine with nothing but a GPU driver and glvnd's loader can run both
// the renderer and the kernels. Every OpenGL entry point comes from proc_address() (eglGetProcAddress, which EGL
// 1.5 defines for core functions too), never from libGL or libOpenGL.
#pragma once

#include "temporal/core/error.h"

#include <memory>
#include <string>
#include <vector>

namespace temporal::gpu::egl {

// One device of the device platform, in eglQueryDevicesEXT's order.
struct Device {
  int index = -1;
  std::string extensions;  // the device's EGL_EXTENSIONS (eglQueryDeviceStringEXT); empty when not queryable
  bool software = false;   // EGL_MESA_device_software: Mesa's llvmpipe, kernels on CPU threads
};

// The devices (possibly none). Fails when libEGL.so.1 cannot be loaded or EGL lacks the device platform
// (EGL_EXT_platform_device with EGL_EXT_device_enumeration or _base); the message says which and what to install.
Expected<std::vector<Device>> devices();

// The device to use when none is asked for: the first hardware device, else the first device; -1 for none.
int default_device(const std::vector<Device>& devices);

// Whether `list` (a space-separated extension string) holds `word` as a whole word.
bool has_extension(const char* list, const char* word);

// An OpenGL 4.5 core-profile context on one device, surfaceless: no window and no pbuffer, rendering and compute
// go to FBOs and buffers. Not copyable; current on one thread at a time.
class SurfacelessContext {
 public:
  // Makes the context on device `index` (an index into devices()) and makes it current on the calling thread. Fails
  // with the EGL step that failed and its error code (eglInitialize, no EGL_KHR_surfaceless_context, no desktop
  // OpenGL config, no 4.5 core context, eglMakeCurrent).
  static Expected<std::unique_ptr<SurfacelessContext>> create(int index);
  // Releases the current binding when it is this context, then destroys it. The display is not terminated: EGL
  // returns one EGLDisplay per device to every caller in the process, and eglTerminate would end their contexts.
  ~SurfacelessContext();
  SurfacelessContext(const SurfacelessContext&) = delete;
  SurfacelessContext& operator=(const SurfacelessContext&) = delete;

  int device_index() const { return index_; }
  // Whether EGL's current context on this thread is this one.
  bool is_current() const;
  // Binds it on the calling thread (always, even when EGL reports it current: OSMesa shares Mesa's dispatch and
  // may have taken it; render/gl_context.cpp). Internal error with the EGL error code when eglMakeCurrent fails.
  Status make_current() const;

  // An OpenGL or EGL entry point by name, null when the driver has none. Valid once devices() succeeded.
  static void* proc_address(const char* name);

 private:
  SurfacelessContext() = default;
  void* display_ = nullptr;  // EGLDisplay
  void* context_ = nullptr;  // EGLContext
  int index_ = -1;
};

}  // namespace temporal::gpu::egl
