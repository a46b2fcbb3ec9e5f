// Compute programs: GLSL 4.50 compute shaders assembled from shared snippets (temporal/gpu/glsl.h) and the
// kernel's own source, compiled and linked with their errors returned with the driver's log.
#pragma once

#include "temporal/core/error.h"
#include "temporal/gpu/context.h"

#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace temporal::gpu {

// Work-group size of the 2D image kernels (gpu::glsl::prelude declares it): 16 x 16 invocations.
inline constexpr int kGroupSize = 16;

class Program {
 public:
  Program() = default;
  // Compiles the concatenation of `parts` (the first part starts with gpu::glsl::prelude()). `name` names the
  // kernel in the error, whose message holds the compile or link log with line numbers of the assembled source.
  static Expected<Program> compile(std::shared_ptr<Context> context, const std::string& name,
                                   const std::vector<std::string_view>& parts);
  ~Program();
  Program(Program&& other) noexcept;
  Program& operator=(Program&& other) noexcept;
  Program(const Program&) = delete;
  Program& operator=(const Program&) = delete;

  // Makes the program current (and its context); the uniform setters and dispatch act on it.
  Status use() const;
  // Uniforms by name (a name the compiler removed as unused is ignored).
  void set(const char* name, int v) const;
  void set(const char* name, unsigned v) const;
  void set(const char* name, float v) const;
  void set(const char* name, float x, float y) const;
  void set(const char* name, const float* v, int count) const;  // float[count]
  void set_int2(const char* name, int x, int y) const;           // ivec2
  // Sets u_size = (width, height), dispatches ceil(width / 16) x ceil(height / 16) work groups and makes their
  // storage writes visible to the next dispatch and to buffer reads.
  Status dispatch(int width, int height) const;
  // Dispatches `groups_x` x `groups_y` work groups (kernels with their own work-group size).
  Status dispatch_groups(unsigned groups_x, unsigned groups_y) const;

  const std::string& name() const { return name_; }
  const std::string& source() const { return source_; }

 private:
  std::shared_ptr<Context> context_;
  unsigned program_ = 0;
  std::string name_, source_;
};

}  // namespace temporal::gpu
