// The shared GLSL snippets (temporal/gpu/glsl.h). The reprojection snippet mirrors temporal/core/reproject.h
// and src/core/reproject.cpp line for line: same tests, same operation order, same constants. Where GLSL cannot
// match the C++ bit for bit (the driver may fuse a * b + c into an FMA, or not, where GCC with -march=native
// does), the kernels' tests bound the difference (docs/gpu.md, "Tolerances").
#include "temporal/gpu/glsl.h"

#include "temporal/core/image.h"
#include "temporal/core/reproject.h"

#include <cstdio>

namespace temporal::gpu::glsl {

static_assert(kMaxSampleMagnitude == 1e10f, "is_sample in the prelude spells kMaxSampleMagnitude");

std::string_view prelude() {
  static const std::string text = R"(#version 450
layout(local_size_x = 16, local_size_y = 16) in;
uniform ivec2 u_size;

bool is_finite_bits(float v) { return (floatBitsToUint(v) & 0x7f800000u) != 0x7f800000u; }
// usable_sample of temporal/core/image.h: finite and at most kMaxSampleMagnitude (1e10) in magnitude.
bool is_sample(float v) { return is_finite_bits(v) && abs(v) <= 1e10; }

// The invocation's pixel; false outside the image (the last groups overhang it).
bool pixel_index(out ivec2 p, out uint i) {
  p = ivec2(gl_GlobalInvocationID.xy);
  i = uint(p.y) * uint(u_size.x) + uint(p.x);
  return p.x < u_size.x && p.y < u_size.y;
}

layout(std430, binding = 15) buffer Counters { uint counters[]; };
shared uint s_counters[4];
// Per-group counts, one atomic per group and counter. Every invocation of the group must call count_begin() and
// count_end() (they contain barriers), including those outside the image.
void count_begin() {
  if (gl_LocalInvocationIndex < 4u) s_counters[gl_LocalInvocationIndex] = 0u;
  barrier();
}
void count_add(int k, bool b) { if (b) atomicAdd(s_counters[k], 1u); }
void count_end() {
  barrier();
  if (gl_LocalInvocationIndex < 4u && s_counters[gl_LocalInvocationIndex] != 0u)
    atomicAdd(counters[gl_LocalInvocationIndex], s_counters[gl_LocalInvocationIndex]);
}
)";
  return text;
}

std::string float_storage(int binding, const char* name) {
  const std::string b = std::to_string(binding), n = name;
  return "layout(std430, binding = " + b + ") buffer " + n + "_F { float " + n + "[]; };\n";
}

std::string storage(int binding, const char* name) {
  const std::string b = std::to_string(binding), n = name;
  return float_storage(binding, name) + "layout(std430, binding = " + b + ") buffer " + n + "_U { uint " + n +
         "_u[]; };\n";
}

std::string float_constant(const char* name, float value) {
  char line[160];
  std::snprintf(line, sizeof line, "const float %s = %.9g;\n", name, double(value));
  return line;
}

namespace {
// The GLSL twin of temporal/core/reproject.h (every kernel includes it through reproject()); kMinHitWeight is
// prepended from the C++ constant so that the two cannot drift.
constexpr const char* kReprojectGlsl = R"(
#ifndef REPROJECT_PREV_Z
#define REPROJECT_PREV_Z(q) 0.0
#endif
#ifndef REPROJECT_PREV_ID
#define REPROJECT_PREV_ID(q) 0u
#endif

// The off-screen rule: inside the previous image's pixel area. False for NaN.
bool reproject_on_screen(vec2 f) {
  return f.x >= -0.5 && f.y >= -0.5 && f.x < float(u_size.x) - 0.5 && f.y < float(u_size.y) - 0.5;
}

// Four taps: plane offsets and weights.
struct Taps {
  int q[4];
  float w[4];
};

// reproject_row's first step for pixel p: the bilinear taps at p + motion, weights 0 for taps outside the image
// and for all four when the motion is not finite (or absurd, >= 1e6 pixels) or the position is off screen.
Taps reproject_taps(ivec2 p, vec2 motion) {
  const int W = u_size.x, H = u_size.y;
  const bool finite = abs(motion.x) < 1e6 && abs(motion.y) < 1e6;
  const vec2 m = finite ? motion : vec2(0.0);
  const float u = float(p.x) + m.x, v = float(p.y) + m.y;
  const bool ok = finite && u >= -0.5 && v >= -0.5 && u < float(W) - 0.5 && v < float(H) - 0.5;
  const float fu = floor(u), fv = floor(v);
  const float ax = u - fu, ay = v - fv;
  const int x0 = int(fu), y0 = int(fv);
  const bool ix0 = x0 >= 0 && x0 < W, ix1 = x0 + 1 >= 0 && x0 + 1 < W;
  const bool iy0 = y0 >= 0 && y0 < H, iy1 = y0 + 1 >= 0 && y0 + 1 < H;
  const int cx0 = clamp(x0, 0, W - 1), cx1 = clamp(x0 + 1, 0, W - 1);
  const int cy0 = clamp(y0, 0, H - 1), cy1 = clamp(y0 + 1, 0, H - 1);
  Taps t;
  t.q[0] = cy0 * W + cx0;
  t.q[1] = cy0 * W + cx1;
  t.q[2] = cy1 * W + cx0;
  t.q[3] = cy1 * W + cx1;
  t.w[0] = (ok && ix0 && iy0) ? (1.0 - ax) * (1.0 - ay) : 0.0;
  t.w[1] = (ok && ix1 && iy0) ? ax * (1.0 - ay) : 0.0;
  t.w[2] = (ok && ix0 && iy1) ? (1.0 - ax) * ay : 0.0;
  t.w[3] = (ok && ix1 && iy1) ? ax * ay : 0.0;
  return t;
}

// same_surface(): relative depth difference against the larger depth (z > zp ? z : zp, as the C++ row kernel).
bool reproject_same_depth(float z, float zp, float tol) { return abs(z - zp) <= tol * (z > zp ? z : zp); }

// reproject_row's second step: each tap tested on its own against the previous frame (REPROJECT_PREV_Z / _ID),
// failed taps dropped, the rest renormalised. False, all weights 0, on a miss (surviving weight < kMinHitWeight).
bool reproject_test(inout Taps t, float z, uint id, bool use_depth, bool use_ids, float tol) {
  float e[4];
  for (int k = 0; k < 4; ++k) {
    bool ok = true;
    if (use_depth) ok = reproject_same_depth(z, REPROJECT_PREV_Z(t.q[k]), tol);
    if (use_ids) ok = ok && REPROJECT_PREV_ID(t.q[k]) == id;
    e[k] = ok ? t.w[k] : 0.0;
  }
  const float sum = e[0] + e[1] + e[2] + e[3];
  const float inv = sum >= kMinHitWeight ? 1.0 / sum : 0.0;
  for (int k = 0; k < 4; ++k) t.w[k] = e[k] * inv;
  return inv > 0.0;
}

#define REPROJECT_GATHER(buf, base, t)                                                     \
  (t.w[0] * buf[(base) + uint(t.q[0])] + t.w[1] * buf[(base) + uint(t.q[1])] +             \
   t.w[2] * buf[(base) + uint(t.q[2])] + t.w[3] * buf[(base) + uint(t.q[3])])

// reproject::bilinear: the four pixel centres around f, edge taps repeated (clamped); weights sum to 1.
Taps reproject_bilinear(vec2 f) {
  const int W = u_size.x, H = u_size.y;
  const float x0f = floor(f.x), y0f = floor(f.y);
  const float tx = f.x - x0f, ty = f.y - y0f;
  const int x0 = clamp(int(x0f), 0, W - 1), x1 = clamp(int(x0f) + 1, 0, W - 1);
  const int y0 = clamp(int(y0f), 0, H - 1), y1 = clamp(int(y0f) + 1, 0, H - 1);
  Taps t;
  t.q[0] = y0 * W + x0;
  t.q[1] = y0 * W + x1;
  t.q[2] = y1 * W + x0;
  t.q[3] = y1 * W + x1;
  t.w[0] = (1.0 - tx) * (1.0 - ty);
  t.w[1] = tx * (1.0 - ty);
  t.w[2] = (1.0 - tx) * ty;
  t.w[3] = tx * ty;
  return t;
}

// reproject::nearest: std::lround (halves away from zero), clamped to the image.
int reproject_lround(float v) { return int(v < 0.0 ? -floor(-v + 0.5) : floor(v + 0.5)); }
int reproject_nearest(vec2 f) {
  const int x = clamp(reproject_lround(f.x), 0, u_size.x - 1);
  const int y = clamp(reproject_lround(f.y), 0, u_size.y - 1);
  return y * u_size.x + x;
}

// reproject::catmull_rom_weights and catmull_rom: 4x4 taps, edge taps repeated.
void catmull_rom_weights(float t, out float w[4]) {
  const float t2 = t * t, t3 = t2 * t;
  w[0] = 0.5 * (-t3 + 2.0 * t2 - t);
  w[1] = 0.5 * (3.0 * t3 - 5.0 * t2 + 2.0);
  w[2] = 0.5 * (-3.0 * t3 + 4.0 * t2 + t);
  w[3] = 0.5 * (t3 - t2);
}
struct CatmullRom {
  int row[4];  // offsets of the four rows
  int col[4];
  float wx[4], wy[4];
};
CatmullRom catmull_rom(vec2 f) {
  const float x0f = floor(f.x), y0f = floor(f.y);
  CatmullRom c;
  catmull_rom_weights(f.x - x0f, c.wx);
  catmull_rom_weights(f.y - y0f, c.wy);
  const int x0 = int(x0f), y0 = int(y0f);
  for (int k = 0; k < 4; ++k) {
    c.col[k] = clamp(x0 - 1 + k, 0, u_size.x - 1);
    c.row[k] = clamp(y0 - 1 + k, 0, u_size.y - 1) * u_size.x;
  }
  return c;
}
// result = the Catmull-Rom fetch of plane `base` of `buf` (the order of the C++ operator()).
#define CATMULL_ROM_FETCH(result, buf, base, c)                                                        \
  {                                                                                                    \
    float s_ = 0.0;                                                                                    \
    for (int j_ = 0; j_ < 4; ++j_) {                                                                   \
      const uint r_ = (base) + uint(c.row[j_]);                                                        \
      const float h_ = c.wx[0] * buf[r_ + uint(c.col[0])] + c.wx[1] * buf[r_ + uint(c.col[1])] +       \
                       c.wx[2] * buf[r_ + uint(c.col[2])] + c.wx[3] * buf[r_ + uint(c.col[3])];        \
      s_ += c.wy[j_] * h_;                                                                             \
    }                                                                                                  \
    result = s_;                                                                                       \
  }

// reproject::expect_depth: the warped depth (prevDepth.Z) at its tolerance when the frame has it, else the
// current depth at the method's tolerance.
float expect_depth(float depth, float warped_depth, bool has_warped) { return has_warped ? warped_depth : depth; }
float expect_tolerance(float tol, float warped_tol, bool has_warped) { return has_warped ? warped_tol : tol; }
)";
}  // namespace

std::string_view reproject() {
  static const std::string text = float_constant("kMinHitWeight", reproject::kMinHitWeight) + kReprojectGlsl;
  return text;
}

std::string_view ycgco_box() {
  return R"(
void to_box(float v[BOX_C], out float b[BOX_C]) {
#if BOX_C == 3
  b[0] = 0.25 * v[0] + 0.5 * v[1] + 0.25 * v[2];
  b[1] = -0.25 * v[0] + 0.5 * v[1] - 0.25 * v[2];
  b[2] = 0.5 * v[0] - 0.5 * v[2];
#else
  b[0] = v[0];
#endif
}
void from_box(float b[BOX_C], out float v[BOX_C]) {
#if BOX_C == 3
  const float t = b[0] - b[1];
  v[0] = t + b[2];
  v[1] = b[0] + b[1];
  v[2] = t - b[2];
#else
  v[0] = b[0];
#endif
}
)";
}

std::string_view std_min_max() {
  return R"(
float min_(float a, float b) { return b < a ? b : a; }
float max_(float a, float b) { return a < b ? b : a; }
)";
}

}  // namespace temporal::gpu::glsl
