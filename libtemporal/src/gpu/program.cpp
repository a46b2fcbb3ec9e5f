#include "temporal/gpu/program.h"

#include <utility>

namespace temporal::gpu {

Expected<Program> Program::compile(std::shared_ptr<Context> context, const std::string& name,
                                   const std::vector<std::string_view>& parts) {
  if (!context) return Error::internal("gpu::Program: no context");
  if (Status s = context->make_current(); !s) return s.error();
  Program p;
  p.context_ = std::move(context);
  p.name_ = name;
  for (auto part : parts) p.source_ += part;
  const GlFunctions& gl = p.context_->gl();
  const GLuint shader = gl.CreateShader(GL_COMPUTE_SHADER);
  const char* text = p.source_.c_str();
  gl.ShaderSource(shader, 1, &text, nullptr);
  gl.CompileShader(shader);
  GLint ok = 0;
  gl.GetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    GLint length = 0;
    gl.GetShaderiv(shader, GL_INFO_LOG_LENGTH, &length);
    std::string log(std::size_t(std::max(length, 1)), '\0');
    gl.GetShaderInfoLog(shader, GLsizei(log.size()), nullptr, log.data());
    gl.DeleteShader(shader);
    return Error::internal("gpu: kernel '" + name + "' does not compile:\n" + log.c_str());
  }
  p.program_ = gl.CreateProgram();
  gl.AttachShader(p.program_, shader);
  gl.LinkProgram(p.program_);
  gl.DeleteShader(shader);
  gl.GetProgramiv(p.program_, GL_LINK_STATUS, &ok);
  if (!ok) {
    GLint length = 0;
    gl.GetProgramiv(p.program_, GL_INFO_LOG_LENGTH, &length);
    std::string log(std::size_t(std::max(length, 1)), '\0');
    gl.GetProgramInfoLog(p.program_, GLsizei(log.size()), nullptr, log.data());
    return Error::internal("gpu: kernel '" + name + "' does not link:\n" + log.c_str());
  }
  if (Status s = p.context_->check("compiling a kernel"); !s) return s.error();
  return p;
}

Program::~Program() {
  if (program_ && context_ && context_->make_current()) context_->gl().DeleteProgram(program_);
}

Program::Program(Program&& other) noexcept { *this = std::move(other); }

Program& Program::operator=(Program&& other) noexcept {
  if (this != &other) {
    if (program_ && context_ && context_->make_current()) context_->gl().DeleteProgram(program_);
    context_ = std::move(other.context_);
    program_ = std::exchange(other.program_, 0u);
    name_ = std::move(other.name_);
    source_ = std::move(other.source_);
  }
  return *this;
}

Status Program::use() const {
  if (!program_) return Error::internal("gpu::Program::use: no program");
  if (Status s = context_->make_current(); !s) return s;
  context_->gl().UseProgram(program_);
  return Status::ok();
}

void Program::set(const char* name, int v) const {
  context_->gl().Uniform1i(context_->gl().GetUniformLocation(program_, name), v);
}
void Program::set(const char* name, unsigned v) const {
  context_->gl().Uniform1ui(context_->gl().GetUniformLocation(program_, name), v);
}
void Program::set(const char* name, float v) const {
  context_->gl().Uniform1f(context_->gl().GetUniformLocation(program_, name), v);
}
void Program::set(const char* name, float x, float y) const {
  context_->gl().Uniform2f(context_->gl().GetUniformLocation(program_, name), x, y);
}
void Program::set(const char* name, const float* v, int count) const {
  context_->gl().Uniform1fv(context_->gl().GetUniformLocation(program_, name), count, v);
}

void Program::set_int2(const char* name, int x, int y) const {
  context_->gl().Uniform2i(context_->gl().GetUniformLocation(program_, name), x, y);
}

Status Program::dispatch(int width, int height) const {
  // Every image kernel reads its size from u_size (gpu::glsl::prelude); the dispatch sets it so that the size
  // and the grid cannot disagree.
  const GlFunctions& gl = context_->gl();
  gl.Uniform2i(gl.GetUniformLocation(program_, "u_size"), width, height);
  return dispatch_groups(unsigned((width + kGroupSize - 1) / kGroupSize),
                         unsigned((height + kGroupSize - 1) / kGroupSize));
}

Status Program::dispatch_groups(unsigned groups_x, unsigned groups_y) const {
  const GlFunctions& gl = context_->gl();
  gl.DispatchCompute(groups_x, groups_y, 1);
  gl.MemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
  return context_->check(name_.c_str());
}

}  // namespace temporal::gpu
