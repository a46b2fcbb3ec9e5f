// GLSL snippets shared by every kernel. A kernel's source is
//   prelude() + storage(...) for each buffer + [the REPROJECT_* macros it needs] + reproject() + its own main().
#pragma once

#include <string>
#include <string_view>

namespace temporal::gpu::glsl {

// "#version 450", the 16 x 16 work-group size, and helpers every kernel uses:
//   is_finite_bits(v)  v is neither NaN nor +-Inf, decided on the bits (immune to a compiler that assumes no NaN)
//   is_sample(v)       is_finite_bits(v) and |v| <= kMaxSampleMagnitude (temporal/core/image.h usable_sample)
//   pixel_index()      the invocation's pixel (gl_GlobalInvocationID.xy) and whether it lies inside u_size
//   count_add(k, b)    adds b (0 or 1) to counter k (0..3) of the `counters` buffer (binding 15), reduced per
//                      work group in shared memory so that each group issues one atomic per counter
// Uniforms: ivec2 u_size (the image size; set by the kernel's host code).
std::string_view prelude();

// Declares shader storage buffer `name` at `binding` twice over the same binding: `name[]` as float and
// `name_u[]` as uint (ids), so one ImageBuffer holds both kinds of planes.
std::string storage(int binding, const char* name);

// Declares shader storage buffer `name` at `binding` as float only (`name[]`): one storage block where storage()
// uses two, for a kernel near GL_MAX_COMPUTE_SHADER_STORAGE_BLOCKS (16 on llvmpipe) that reads no ids from it.
std::string float_storage(int binding, const char* name);

// "const float NAME = VALUE;" with VALUE printed with %.9g, which round-trips a float: a C++ constant in a kernel
// with the same bits, so that the host code and the kernel cannot drift.
std::string float_constant(const char* name, float value);

// The GLSL version of temporal/core/reproject.h: the same rules and constants, one definition for every kernel.
//   reproject_on_screen(f)                          the off-screen rule
//   Taps reproject_taps(p, motion)                  reproject_row's taps: NaN / Inf / |m| >= 1e6 motion or off
//                                                   screen -> all weights 0; taps outside the image weight 0
//   bool reproject_test(inout Taps t, z, id, use_depth, use_ids, tol)
//                                                   the per-tap disocclusion test (depth relative to the larger
//                                                   depth, ids), renormalised; false (weights 0) on a miss
//   REPROJECT_GATHER(buf, base, t)                  sum_j t.w[j] buf[base + t.q[j]] (the gather of gather_row)
//   Taps reproject_bilinear(f)                      reproject::bilinear: edge taps repeated, weights sum to 1
//   CatmullRom catmull_rom(f); CATMULL_ROM_FETCH(result, buf, base, c)
//   int reproject_nearest(f)                        reproject::nearest (std::lround: halves away from zero)
//   float expect_depth(depth, warped_depth, has_warped) and expect_tolerance(...): reproject::expect_depth
// The kernel defines REPROJECT_PREV_Z(q) and REPROJECT_PREV_ID(q) (the previous frame's depth and id at plane
// offset q) before this snippet when it tests depth or ids.
std::string_view reproject();

// temporal/core/color.h's to_ycgco_box / from_ycgco_box for BOX_C channels (1 or 3; the kernel defines BOX_C before
// this snippet): void to_box(float v[BOX_C], out float b[BOX_C]) and from_box(b, v), YCgCo for three channels, the
// value itself for one. The box space of phlm's box test and taa's clipping.
std::string_view ycgco_box();

// float min_(a, b) and float max_(a, b): std::min and std::max to the letter (b < a ? b : a and a < b ? b : a), for
// the kernels whose C++ reference takes them where an operand can be NaN (taa's clipping, phlm's box): the result
// is then the first operand, as in C++, which GLSL's min and max do not promise.
std::string_view std_min_max();

}  // namespace temporal::gpu::glsl
