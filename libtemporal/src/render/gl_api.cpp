#include "gl_api.h"

#include <cstdio>
#include <vector>

namespace temporal::render_detail {

Status GlContext::load(void* (*get_proc)(const char*), const char* kind, int device) {
  std::string missing;
#define TEMPORAL_GL_LOAD(type, name)                                     \
  gl_.name = reinterpret_cast<type>(get_proc("gl" #name));               \
  if (!gl_.name) missing += " gl" #name;
  TEMPORAL_GL_FUNCTIONS(TEMPORAL_GL_LOAD)
#undef TEMPORAL_GL_LOAD
  if (!missing.empty()) return Error::internal(std::string(kind) + " lacks OpenGL entry points:" + missing);
  auto str = [&](GLenum e) {
    const GLubyte* s = gl_.GetString(e);
    return s ? std::string(reinterpret_cast<const char*>(s)) : std::string("?");
  };
  info_.context = kind;
  info_.device = device;
  info_.vendor = str(GL_VENDOR);
  info_.renderer = str(GL_RENDERER);
  info_.version = str(GL_VERSION);
  return {};
}

std::string GlContext::description() const {
  return info_.renderer + ", OpenGL " + info_.version + " (" + info_.context +
         (info_.device >= 0 ? " device " + std::to_string(info_.device) : std::string()) + ")";
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
