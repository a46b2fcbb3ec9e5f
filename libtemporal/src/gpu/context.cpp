// The gpu stage's compute context: a surfaceless OpenGL 4.5 core context on an EGL device (temporal/gpu/egl.h, which
// the renderer's EGL context uses too), with the GL function table every kernel calls through.
//
// libEGL is opened at run time (egl.cpp), not linked: the method stages link this stage, and their CPU kernel
// benchmarks must stay free of display libraries (kernel_dependencies.*, tests/benchmarks/CMakeLists.txt); a
// program that never asks for the GPU never loads libEGL, and one that does on a machine without it gets an error.
#include "temporal/gpu/context.h"

#include "temporal/gpu/egl.h"

#include <cstdio>
#include <string>
#include <vector>

namespace temporal::gpu {
namespace {

std::string hex(unsigned v) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%04x", v);
  return buf;
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
  // Errors of this step are usage errors: the machine cannot run `--device gpu` (no libEGL, no device, no 4.5 core
  // context), whatever EGL step failed.
  // (egl.h's own usage errors already say what to install; its failed steps get the hint here.)
  auto unusable = [](const Error& e) {
    return Error::usage("--device gpu: " + e.message +
                        (e.kind == ErrorKind::Usage ? ""
                                                    : "; this machine has no usable EGL device (install libegl1 and a "
                                                      "driver: libegl-mesa0 for llvmpipe)"));
  };
  auto devices = egl::devices();
  if (!devices) return unusable(devices.error());
  if (devices->empty()) return unusable(Error::internal("eglQueryDevicesEXT lists no EGL device"));
  const int count = int(devices->size());
  if (options.device >= count)
    return Error::usage("--gpu-device " + std::to_string(options.device) + ": EGL lists " + std::to_string(count) +
                        " device(s) (0-" + std::to_string(count - 1) + ")");
  const int pick = options.device >= 0 ? options.device : egl::default_device(*devices);
  auto surfaceless = egl::SurfacelessContext::create(pick);
  if (!surfaceless) return unusable(surfaceless.error());
  std::shared_ptr<Context> ctx(new Context());
  ctx->device_index_ = pick;
  ctx->software_ = (*devices)[std::size_t(pick)].software;
  ctx->egl_ = std::move(*surfaceless);
#define TEMPORAL_GPU_GL_LOAD(type, name)                                                                  \
  ctx->gl_.name = reinterpret_cast<type>(egl::SurfacelessContext::proc_address("gl" #name));                                 \
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

Context::~Context() = default;  // egl::SurfacelessContext releases the EGL context

Status Context::make_current() const {
  if (egl_->is_current()) return Status::ok();
  if (Status s = egl_->make_current(); !s) return Error::internal("gpu: " + s.error().message);
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
