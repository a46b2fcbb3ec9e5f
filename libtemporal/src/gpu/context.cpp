// EGL device platform -> OpenGL 4.5 core context, surfaceless (the recipe of shared/tools/egl-probe.c, verified on
// llvmpipe and on an NVIDIA H200 driver-only machine).
//
// libEGL is opened at run time (dlopen), not linked: the method stages link this stage, and their CPU kernel
// benchmarks must stay free of display libraries (kernel_dependencies.*, tests/benchmarks/CMakeLists.txt); a
// program that never asks for the GPU never loads libEGL, and one that does on a machine without it gets an error.
#include "temporal/gpu/context.h"

#define EGL_NO_PROTOTYPES
#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <dlfcn.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <type_traits>
#include <string_view>
#include <vector>

namespace temporal::gpu {
namespace {

// The EGL 1.5 entry points this file calls, from libEGL.so.1 (glvnd's dispatcher, or a vendor's libEGL).
struct Egl {
  PFNEGLGETPROCADDRESSPROC GetProcAddress = nullptr;
  PFNEGLINITIALIZEPROC Initialize = nullptr;
  PFNEGLBINDAPIPROC BindAPI = nullptr;
  PFNEGLCREATECONTEXTPROC CreateContext = nullptr;
  PFNEGLDESTROYCONTEXTPROC DestroyContext = nullptr;
  PFNEGLMAKECURRENTPROC MakeCurrent = nullptr;
  PFNEGLGETCURRENTCONTEXTPROC GetCurrentContext = nullptr;
  PFNEGLGETERRORPROC GetError = nullptr;
  std::string error;  // why loading failed; empty when loaded
};

// Loaded once per process (the handle is never closed: contexts may live until exit).
const Egl& egl() {
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
    load(e.Initialize, "eglInitialize");
    load(e.BindAPI, "eglBindAPI");
    load(e.CreateContext, "eglCreateContext");
    load(e.DestroyContext, "eglDestroyContext");
    load(e.MakeCurrent, "eglMakeCurrent");
    load(e.GetCurrentContext, "eglGetCurrentContext");
    load(e.GetError, "eglGetError");
    return e;
  }();
  return loaded;
}

std::string hex(unsigned v) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%04x", v);
  return buf;
}

Error egl_error(const std::string& step) {
  return Error::usage("--device gpu: " + step + " failed (EGL error " + hex(unsigned(egl().GetError())) +
                      "); this machine has no usable EGL device (install libegl-mesa0 for llvmpipe)");
}

// Whether GL_TIME_ELAPSED reports a dispatch's time: a small kernel that does measurable work, timed once.
// llvmpipe reads 0 (its queries are not implemented for compute); hardware drivers read nanoseconds.
bool probe_timer_queries(const GlFunctions& gl) {
  static const char* src =
      "#version 450\nlayout(local_size_x = 64) in;\nlayout(std430, binding = 0) buffer B { float v[]; };\n"
      "void main() { uint i = gl_GlobalInvocationID.x; float x = v[i];\n"
      "  for (int k = 0; k < 256; ++k) x = x * 0.999 + 0.001;\n  v[i] = x; }\n";
  const GLuint shader = gl.CreateShader(GL_COMPUTE_SHADER);
  gl.ShaderSource(shader, 1, &src, nullptr);
  gl.CompileShader(shader);
  GLint ok = 0;
  gl.GetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  const GLuint program = gl.CreateProgram();
  gl.AttachShader(program, shader);
  gl.LinkProgram(program);
  gl.DeleteShader(shader);
  GLint linked = 0;
  gl.GetProgramiv(program, GL_LINK_STATUS, &linked);
  bool works = false;
  if (ok && linked) {
    constexpr GLsizeiptr kCount = 1 << 16;
    GLuint buffer = 0, query = 0;
    gl.GenBuffers(1, &buffer);
    gl.BindBuffer(GL_SHADER_STORAGE_BUFFER, buffer);
    gl.BufferData(GL_SHADER_STORAGE_BUFFER, kCount * 4, nullptr, GL_DYNAMIC_DRAW);
    gl.BindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, buffer);
    gl.UseProgram(program);
    gl.GenQueries(1, &query);
    gl.BeginQuery(GL_TIME_ELAPSED, query);
    gl.DispatchCompute(GLuint(kCount / 64), 1, 1);
    gl.EndQuery(GL_TIME_ELAPSED);
    GLuint64 ns = 0;
    gl.GetQueryObjectui64v(query, GL_QUERY_RESULT, &ns);
    works = ns > 0 && gl.GetError() == GL_NO_ERROR;
    gl.DeleteQueries(1, &query);
    gl.DeleteBuffers(1, &buffer);
    gl.UseProgram(0);
  }
  gl.DeleteProgram(program);
  while (gl.GetError() != GL_NO_ERROR) {
  }
  return works;
}

}  // namespace

Status Context::ensure(std::shared_ptr<Context>& context) {
  if (context) return Status::ok();
  auto created = create();
  if (!created) return created.error();
  context = std::move(*created);
  return Status::ok();
}

Expected<std::shared_ptr<Context>> Context::create(const ContextOptions& options) {
  if (!egl().error.empty()) return Error::usage("--device gpu: " + egl().error);
  auto query_devices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(egl().GetProcAddress("eglQueryDevicesEXT"));
  auto query_string =
      reinterpret_cast<PFNEGLQUERYDEVICESTRINGEXTPROC>(egl().GetProcAddress("eglQueryDeviceStringEXT"));
  auto platform_display =
      reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(egl().GetProcAddress("eglGetPlatformDisplayEXT"));
  if (!query_devices || !platform_display)
    return Error::usage("--device gpu: EGL has no device enumeration (EGL_EXT_device_enumeration, "
                        "EGL_EXT_platform_device); install libegl1 and a driver (libegl-mesa0 for llvmpipe)");
  EGLDeviceEXT devices[16];
  EGLint count = 0;
  if (!query_devices(16, devices, &count) || count == 0) return egl_error("eglQueryDevicesEXT (no EGL device)");
  std::vector<bool> software(std::size_t(count), false);
  for (EGLint i = 0; i < count; ++i) {
    const char* ext = query_string ? query_string(devices[i], EGL_EXTENSIONS) : nullptr;
    software[std::size_t(i)] = ext && std::strstr(ext, "EGL_MESA_device_software") != nullptr;
  }
  int pick = options.device;
  if (pick >= count) return Error::usage("--gpu-device " + std::to_string(pick) + ": EGL lists " +
                                         std::to_string(count) + " device(s) (0-" + std::to_string(count - 1) + ")");
  if (pick < 0) {
    for (EGLint i = 0; i < count && pick < 0; ++i)
      if (!software[std::size_t(i)]) pick = i;
    if (pick < 0) pick = 0;
  }
  std::shared_ptr<Context> ctx(new Context());
  ctx->device_index_ = pick;
  ctx->software_ = software[std::size_t(pick)];
  EGLDisplay display = platform_display(EGL_PLATFORM_DEVICE_EXT, devices[pick], nullptr);
  if (display == EGL_NO_DISPLAY) return egl_error("eglGetPlatformDisplayEXT");
  EGLint major = 0, minor = 0;
  if (!egl().Initialize(display, &major, &minor)) return egl_error("eglInitialize");
  if (!egl().BindAPI(EGL_OPENGL_API)) return egl_error("eglBindAPI(EGL_OPENGL_API)");
  const EGLint attributes[] = {EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 5,
                               EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
  EGLContext context = egl().CreateContext(display, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, attributes);
  if (context == EGL_NO_CONTEXT) return egl_error("eglCreateContext (OpenGL 4.5 core, no config)");
  ctx->display_ = display;
  ctx->context_ = context;
  if (!egl().MakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context))
    return egl_error("eglMakeCurrent (surfaceless)");
#define TEMPORAL_GPU_GL_LOAD(type, name)                                                                  \
  ctx->gl_.name = reinterpret_cast<type>(egl().GetProcAddress("gl" #name));                                 \
  if (!ctx->gl_.name) return Error::usage("--device gpu: the EGL device has no entry point gl" #name);
  TEMPORAL_GPU_GL_FUNCTIONS(TEMPORAL_GPU_GL_LOAD)
#undef TEMPORAL_GPU_GL_LOAD
  const GlFunctions& gl = ctx->gl_;
  auto str = [&](GLenum e) {
    const auto* s = reinterpret_cast<const char*>(gl.GetString(e));
    return std::string(s ? s : "");
  };
  ctx->renderer_ = str(GL_RENDERER);
  ctx->vendor_ = str(GL_VENDOR);
  ctx->version_ = str(GL_VERSION);
  GLint64 max_storage = 0;
  gl.GetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &max_storage);
  ctx->max_storage_bytes_ = max_storage;
  if (Status s = ctx->check("context creation"); !s) return s.error();
  // llvmpipe runs kernels on CPU threads; its GL_TIME_ELAPSED read 0 in shared/tools/egl-probe.c and reads a
  // non-zero value for other kernels, so it is not trusted there: the software device is timed by the wall clock
  // after glFinish (which is what its kernels cost on this CPU).
  ctx->timer_queries_ = !ctx->software_ && probe_timer_queries(gl);
  return ctx;
}

Context::~Context() {
  // The display is not terminated: EGL returns the same EGLDisplay for a device to every caller in the process, so
  // eglTerminate would end the other contexts on it too. Its resources go with the process.
  if (display_ && context_) {
    if (egl().GetCurrentContext() == context_)
      egl().MakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    egl().DestroyContext(display_, context_);
  }
}

Status Context::make_current() const {
  if (egl().GetCurrentContext() == context_) return Status::ok();
  if (!egl().MakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_))
    return Error::internal("gpu: eglMakeCurrent failed (EGL error " + hex(unsigned(egl().GetError())) + ")");
  return Status::ok();
}

std::string Context::description() const { return renderer_ + ", OpenGL " + version_; }

Status Context::check(const char* where) const {
  const GLenum e = gl_.GetError();
  if (e == GL_NO_ERROR) return Status::ok();
  while (gl_.GetError() != GL_NO_ERROR) {
  }
  return Error::internal(std::string("gpu: OpenGL error ") + hex(e) + " in " + where);
}

}  // namespace temporal::gpu
