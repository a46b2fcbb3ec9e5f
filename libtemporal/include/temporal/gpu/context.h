// The gpu stage: GLSL 4.50 compute kernels in an OpenGL 4.5 core context made through EGL, without a window
// (docs/gpu.md). The same code runs on a hardware device (NVIDIA, AMD, Intel through their EGL drivers) and on
// Mesa's llvmpipe (the EGL_MESA_device_software device), which CI uses.
//
// Why a function table: libOSMesa (the renderer) and libGL (VTK) both export every gl* symbol, and a process that
// loads one of them first would send direct gl* calls to a library without a current context. Every entry point
// used here is loaded through eglGetProcAddress, and libEGL itself (glvnd's dispatcher) is opened at run time on
// the first Context::create (temporal/gpu/egl.h, shared with the renderer's EGL context): the stage links no display library (the method stages link it, and their CPU kernel
// benchmarks must run where no display library is installed), and works whatever else the program links.
//
// Threading: an EGL context is current on one thread at a time. Every object of this stage calls
// Context::make_current() before it issues GL calls, so one context may serve several methods on one thread;
// two threads must not use one context at the same time.
#pragma once

#include "temporal/core/error.h"

#include <GL/glcorearb.h>

#include <memory>
#include <string>

namespace temporal::gpu {

namespace egl {
class SurfacelessContext;  // temporal/gpu/egl.h
}

// X(PFN type, member name): the OpenGL 4.5 core entry points of the compute kernels.
#define TEMPORAL_GPU_GL_FUNCTIONS(X)                   \
  X(PFNGLGETSTRINGPROC, GetString)                     \
  X(PFNGLGETINTEGERVPROC, GetIntegerv)                 \
  X(PFNGLGETINTEGERI_VPROC, GetIntegeri_v)             \
  X(PFNGLGETINTEGER64VPROC, GetInteger64v)             \
  X(PFNGLGETERRORPROC, GetError)                       \
  X(PFNGLFINISHPROC, Finish)                           \
  X(PFNGLFLUSHPROC, Flush)                             \
  X(PFNGLGENBUFFERSPROC, GenBuffers)                   \
  X(PFNGLDELETEBUFFERSPROC, DeleteBuffers)             \
  X(PFNGLBINDBUFFERPROC, BindBuffer)                   \
  X(PFNGLBINDBUFFERBASEPROC, BindBufferBase)           \
  X(PFNGLBUFFERDATAPROC, BufferData)                   \
  X(PFNGLBUFFERSUBDATAPROC, BufferSubData)             \
  X(PFNGLGETBUFFERSUBDATAPROC, GetBufferSubData)       \
  X(PFNGLCOPYBUFFERSUBDATAPROC, CopyBufferSubData)     \
  X(PFNGLCLEARBUFFERDATAPROC, ClearBufferData)         \
  X(PFNGLCREATESHADERPROC, CreateShader)               \
  X(PFNGLSHADERSOURCEPROC, ShaderSource)               \
  X(PFNGLCOMPILESHADERPROC, CompileShader)             \
  X(PFNGLGETSHADERIVPROC, GetShaderiv)                 \
  X(PFNGLGETSHADERINFOLOGPROC, GetShaderInfoLog)       \
  X(PFNGLDELETESHADERPROC, DeleteShader)               \
  X(PFNGLCREATEPROGRAMPROC, CreateProgram)             \
  X(PFNGLATTACHSHADERPROC, AttachShader)               \
  X(PFNGLLINKPROGRAMPROC, LinkProgram)                 \
  X(PFNGLGETPROGRAMIVPROC, GetProgramiv)               \
  X(PFNGLGETPROGRAMINFOLOGPROC, GetProgramInfoLog)     \
  X(PFNGLDELETEPROGRAMPROC, DeleteProgram)             \
  X(PFNGLUSEPROGRAMPROC, UseProgram)                   \
  X(PFNGLGETUNIFORMLOCATIONPROC, GetUniformLocation)   \
  X(PFNGLUNIFORM1IPROC, Uniform1i)                     \
  X(PFNGLUNIFORM1UIPROC, Uniform1ui)                   \
  X(PFNGLUNIFORM1FPROC, Uniform1f)                     \
  X(PFNGLUNIFORM2FPROC, Uniform2f)                     \
  X(PFNGLUNIFORM2IPROC, Uniform2i)                     \
  X(PFNGLUNIFORM1FVPROC, Uniform1fv)                   \
  X(PFNGLDISPATCHCOMPUTEPROC, DispatchCompute)         \
  X(PFNGLMEMORYBARRIERPROC, MemoryBarrier)             \
  X(PFNGLGENQUERIESPROC, GenQueries)                   \
  X(PFNGLDELETEQUERIESPROC, DeleteQueries)             \
  X(PFNGLBEGINQUERYPROC, BeginQuery)                   \
  X(PFNGLENDQUERYPROC, EndQuery)                       \
  X(PFNGLGETQUERYOBJECTUI64VPROC, GetQueryObjectui64v)

// The function table. Members are named without the `gl` prefix: gl.DispatchCompute(...).
struct GlFunctions {
#define TEMPORAL_GPU_GL_MEMBER(type, name) type name = nullptr;
  TEMPORAL_GPU_GL_FUNCTIONS(TEMPORAL_GPU_GL_MEMBER)
#undef TEMPORAL_GPU_GL_MEMBER
};

struct ContextOptions {
  // EGL device index (eglQueryDevicesEXT order); -1: the first hardware device, else the first software one.
  int device = -1;
};

// An OpenGL 4.5 core context on an EGL device, surfaceless (compute only), and its entry points.
class Context {
 public:
  // Fails with a usage error (the machine cannot run `--device gpu`) when libEGL.so.1 cannot be loaded, EGL has no
  // device, the device index is
  // out of range, the device gives no 4.5 core context, or an entry point is missing; the message says which step
  // failed.
  static Expected<std::shared_ptr<Context>> create(const ContextOptions& options = {});
  // What every kernel factory does with the context it is given: keeps it, or creates one (default options) when
  // it is null. The error is create()'s.
  static Status ensure(std::shared_ptr<Context>& context);
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  const GlFunctions& gl() const { return gl_; }
  // Makes this context current on the calling thread (a no-op when it already is).
  Status make_current() const;

  int device_index() const { return device_index_; }
  bool software() const { return software_; }  // the EGL_MESA_device_software device (llvmpipe)
  const std::string& renderer() const { return renderer_; }  // GL_RENDERER, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"
  const std::string& vendor() const { return vendor_; }
  const std::string& version() const { return version_; }  // GL_VERSION
  // "<renderer>, OpenGL <version>": what a file header records as the device.
  std::string description() const;
  // Whether GL_TIME_ELAPSED queries report the time of a dispatch (probed at creation on hardware devices; false
  // on the software device, whose kernels run on CPU threads and are timed by the wall clock).
  bool timer_queries() const { return timer_queries_; }
  // GL_MAX_SHADER_STORAGE_BLOCK_SIZE: the largest buffer a kernel can address.
  long long max_storage_bytes() const { return max_storage_bytes_; }

  // A pending GL error as an internal error naming `where`; ok when none.
  Status check(const char* where) const;
  // Waits for every command issued so far.
  void finish() const { gl_.Finish(); }

 private:
  Context() = default;
  std::unique_ptr<egl::SurfacelessContext> egl_;
  int device_index_ = -1;
  bool software_ = false;
  bool timer_queries_ = false;
  long long max_storage_bytes_ = 0;
  std::string renderer_, vendor_, version_;
  GlFunctions gl_;
};

}  // namespace temporal::gpu
