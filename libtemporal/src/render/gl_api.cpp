#include "gl_api.h"

#include <GL/osmesa.h>

#include <cstdio>
#include <vector>

namespace temporal::render_detail {

Expected<std::unique_ptr<GlContext>> GlContext::create() {
  // Core profile 4.5 is the highest llvmpipe grants (4.6 is refused, docs/building.md). No depth or
  // stencil in the default framebuffer: every pass renders into its own FBO.
  const int attribs[] = {OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 0, OSMESA_STENCIL_BITS, 0,
                         OSMESA_PROFILE, OSMESA_CORE_PROFILE, OSMESA_CONTEXT_MAJOR_VERSION, 4,
                         OSMESA_CONTEXT_MINOR_VERSION, 5, 0};
  std::unique_ptr<GlContext> ctx(new GlContext());
  ctx->context_ = OSMesaCreateContextAttribs(attribs, nullptr);
  if (!ctx->context_)
    return Error::internal("OSMesa could not create an OpenGL 4.5 core context (is Mesa's llvmpipe installed?)");
  if (!OSMesaMakeCurrent(static_cast<OSMesaContext>(ctx->context_), ctx->dummy_, GL_UNSIGNED_BYTE, 1, 1))
    return Error::internal("OSMesaMakeCurrent failed");
  std::string missing;
#define TEMPORAL_GL_LOAD(type, name)                                                     \
  ctx->gl_.name = reinterpret_cast<type>(OSMesaGetProcAddress("gl" #name));             \
  if (!ctx->gl_.name) missing += " gl" #name;
  TEMPORAL_GL_FUNCTIONS(TEMPORAL_GL_LOAD)
#undef TEMPORAL_GL_LOAD
  if (!missing.empty()) return Error::internal("OSMesa lacks OpenGL entry points:" + missing);
  return ctx;
}

GlContext::~GlContext() {
  if (context_) OSMesaDestroyContext(static_cast<OSMesaContext>(context_));
}

void GlContext::make_current() {
  OSMesaMakeCurrent(static_cast<OSMesaContext>(context_), dummy_, GL_UNSIGNED_BYTE, 1, 1);
}

std::string GlContext::description() const {
  auto str = [&](GLenum e) {
    const GLubyte* s = gl_.GetString(e);
    return s ? std::string(reinterpret_cast<const char*>(s)) : std::string("?");
  };
  return str(GL_RENDERER) + ", OpenGL " + str(GL_VERSION);
}

namespace {
Expected<GLuint> compile(const GlFunctions& gl, GLenum type, const std::string& name, const std::string& source) {
  GLuint shader = gl.CreateShader(type);
  const char* src = source.c_str();
  gl.ShaderSource(shader, 1, &src, nullptr);
  gl.CompileShader(shader);
  GLint ok = 0;
  gl.GetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    GLint len = 0;
    gl.GetShaderiv(shader, GL_INFO_LOG_LENGTH, &len);
    std::vector<char> log(std::size_t(len) + 1, '\0');
    gl.GetShaderInfoLog(shader, len, nullptr, log.data());
    gl.DeleteShader(shader);
    return Error::internal("shader " + name + (type == GL_VERTEX_SHADER ? " (vertex)" : " (fragment)") +
                           " does not compile: " + log.data());
  }
  return shader;
}
}  // namespace

Expected<GLuint> build_program(const GlFunctions& gl, const std::string& name, const std::string& vertex,
                               const std::string& fragment) {
  auto vs = compile(gl, GL_VERTEX_SHADER, name, vertex);
  if (!vs) return vs.error();
  auto fs = compile(gl, GL_FRAGMENT_SHADER, name, fragment);
  if (!fs) {
    gl.DeleteShader(*vs);
    return fs.error();
  }
  GLuint program = gl.CreateProgram();
  gl.AttachShader(program, *vs);
  gl.AttachShader(program, *fs);
  gl.LinkProgram(program);
  gl.DeleteShader(*vs);
  gl.DeleteShader(*fs);
  GLint ok = 0;
  gl.GetProgramiv(program, GL_LINK_STATUS, &ok);
  if (!ok) {
    GLint len = 0;
    gl.GetProgramiv(program, GL_INFO_LOG_LENGTH, &len);
    std::vector<char> log(std::size_t(len) + 1, '\0');
    gl.GetProgramInfoLog(program, len, nullptr, log.data());
    gl.DeleteProgram(program);
    return Error::internal("shader program " + name + " does not link: " + log.data());
  }
  return program;
}

Status check_gl(const GlFunctions& gl, const char* where) {
  const GLenum e = gl.GetError();
  if (e == GL_NO_ERROR) return {};
  char buf[64];
  std::snprintf(buf, sizeof buf, "0x%04x", unsigned(e));
  return Error::internal(std::string("OpenGL error ") + buf + " in " + where + " (please report this)");
}

}  // namespace temporal::render_detail
