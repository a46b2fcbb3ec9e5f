#include "shaders.h"

namespace temporal::render_detail {

const char* const kGeometryVertex = R"GLSL(#version 450 core
layout(location = 0) in vec3 a_position;       // object space (rigid) or world space (deformed)
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec2 a_uv;
layout(location = 3) in vec3 a_prev_position;  // the same vertex in the previous frame
uniform mat4 u_model;
uniform mat4 u_prev_model;
uniform mat3 u_normal_matrix;
uniform mat4 u_view_proj;  // this pass: projection (jittered) * view
uniform mat4 u_cur_vp;     // unjittered current projection * view (motion)
uniform mat4 u_prev_vp;    // unjittered previous projection * view (motion)
uniform mat4 u_view;       // world -> camera (linear depth)
uniform mat4 u_prev_view;  // previous world -> camera (the previous depth of the surface point, prevDepth.Z)
out vec3 v_world;
out vec3 v_normal;
out vec2 v_uv;
out vec4 v_cur;
out vec4 v_prev;
out float v_view_depth;
out float v_prev_view_depth;
void main() {
  vec4 world = u_model * vec4(a_position, 1.0);
  vec4 prev_world = u_prev_model * vec4(a_prev_position, 1.0);
  v_world = world.xyz;
  v_normal = u_normal_matrix * a_normal;
  v_uv = a_uv;
  // Clip positions are interpolated perspective-correctly and divided per fragment: the motion of the
  // surface point under the fragment, not a linear blend of vertex motions in screen space.
  v_cur = u_cur_vp * world;
  // A vertex that did not move gets exactly the current position (static scenes: motion exactly 0, even
  // where the two products would round differently).
  bool same = u_prev_vp == u_cur_vp && u_prev_model == u_model && a_prev_position == a_position;
  v_prev = same ? v_cur : u_prev_vp * prev_world;
  v_view_depth = -(u_view * world).z;
  // The depth this point had in the previous frame (seed 000 section 3.2's warped depth); exactly the current
  // depth when neither the vertex nor the camera moved (the same trick as for motion).
  bool same_depth = u_prev_view == u_view && u_prev_model == u_model && a_prev_position == a_position;
  v_prev_view_depth = same_depth ? v_view_depth : -(u_prev_view * prev_world).z;
  gl_Position = u_view_proj * world;
}
)GLSL";

#define TEMPORAL_MATERIAL_GLSL                                          \
  "uniform vec4 u_base_color;\n"                                        \
  "uniform bool u_has_texture;\n"                                       \
  "uniform sampler2D u_texture;\n"                                      \
  "uniform float u_lod_bias;\n"                                        \
  "uniform bool u_mask;\n"                                              \
  "uniform float u_cutoff;\n"                                           \
  "in vec3 v_world;\n"                                                  \
  "in vec3 v_normal;\n"                                                 \
  "in vec2 v_uv;\n"                                                     \
  "in vec4 v_cur;\n"                                                    \
  "in vec4 v_prev;\n"                                                   \
  "in float v_view_depth;\n"                                            \
  "in float v_prev_view_depth;\n"                                       \
  "vec4 base_color() {\n"                                               \
  "  vec4 c = u_base_color;\n"                                          \
  "  if (u_has_texture) c *= texture(u_texture, v_uv, u_lod_bias);\n"   \
  "  if (u_mask && c.a < u_cutoff) discard;\n"                          \
  "  return c;\n"                                                       \
  "}\n"                                                                 \
  "vec3 facing_normal() {\n"                                            \
  "  vec3 n = normalize(v_normal);\n"                                   \
  "  return gl_FrontFacing ? n : -n;\n"                                 \
  "}\n"

const char* const kGbufferFragment = "#version 450 core\n" TEMPORAL_MATERIAL_GLSL R"GLSL(
layout(location = 0) out vec4 o_albedo;  // rgb linear base colour, a metallic
layout(location = 1) out vec4 o_normal;  // xyz world normal facing the camera, w roughness
layout(location = 2) out vec4 o_motion;  // xy pixels, y down, p_prev = p + motion; z previous view depth
layout(location = 3) out vec4 o_world;   // xyz world position, w linear view depth (> 0; 0 = background)
layout(location = 4) out uint o_id;
uniform vec2 u_size;
uniform uint u_id;
uniform float u_metallic;
uniform float u_roughness;
void main() {
  vec4 base = base_color();
  vec2 cur = v_cur.xy / v_cur.w;
  vec2 prev = v_prev.xy / v_prev.w;
  o_albedo = vec4(base.rgb, u_metallic);
  o_normal = vec4(facing_normal(), u_roughness);
  // NDC -> pixels: x * width / 2 to the right, y * height / 2 up, so image y (down) flips the sign.
  o_motion = vec4((prev.x - cur.x) * 0.5 * u_size.x, (cur.y - prev.y) * 0.5 * u_size.y, v_prev_view_depth, 0.0);
  o_world = vec4(v_world, v_view_depth);
  o_id = u_id;
}
)GLSL";

const char* const kShadowFragment = "#version 450 core\n" TEMPORAL_MATERIAL_GLSL R"GLSL(
void main() { base_color(); }
)GLSL";

#define TEMPORAL_LIGHTS_GLSL                                                                  \
  "#define MAX_LIGHTS 8\n"                                                                    \
  "uniform int u_light_count;\n"                                                              \
  "uniform int u_light_type[MAX_LIGHTS];        // 0 directional, 1 point, 2 spot\n"          \
  "uniform vec3 u_light_position[MAX_LIGHTS];\n"                                              \
  "uniform vec3 u_light_direction[MAX_LIGHTS];  // direction the light travels\n"             \
  "uniform vec3 u_light_color[MAX_LIGHTS];      // colour * intensity\n"                      \
  "uniform float u_light_range[MAX_LIGHTS];\n"                                                \
  "uniform vec2 u_light_cone[MAX_LIGHTS];       // cos(outer), cos(inner)\n"                  \
  "// KHR_lights_punctual range window and spot cone falloff, without 1/d^2.\n"               \
  "float light_window(int i, vec3 l, float dist) {\n"                                         \
  "  float w = 1.0;\n"                                                                        \
  "  if (u_light_range[i] > 0.0) {\n"                                                         \
  "    float r = dist / u_light_range[i];\n"                                                  \
  "    float f = clamp(1.0 - r * r * r * r, 0.0, 1.0);\n"                                     \
  "    w *= f * f;\n"                                                                         \
  "  }\n"                                                                                     \
  "  if (u_light_type[i] == 2) {\n"                                                           \
  "    float cd = dot(u_light_direction[i], -l);\n"                                           \
  "    float t = clamp((cd - u_light_cone[i].x) / max(u_light_cone[i].y - u_light_cone[i].x, 1e-4), 0.0, 1.0);\n" \
  "    w *= t * t;\n"                                                                         \
  "  }\n"                                                                                     \
  "  return w;\n"                                                                             \
  "}\n"                                                                                       \
  "// Irradiance on a surface facing the light (E, lux) and the unit direction l towards it.\n" \
  "vec3 light_incident(int i, vec3 p, out vec3 l) {\n"                                        \
  "  if (u_light_type[i] == 0) { l = -u_light_direction[i]; return u_light_color[i]; }\n"     \
  "  vec3 d = u_light_position[i] - p;\n"                                                     \
  "  float d2 = max(dot(d, d), 1e-8);\n"                                                      \
  "  float dist = sqrt(d2);\n"                                                                \
  "  l = d / dist;\n"                                                                         \
  "  return u_light_color[i] * (light_window(i, l, dist) / d2);\n"                            \
  "}\n"

const char* const kRsmFragment = "#version 450 core\n" TEMPORAL_MATERIAL_GLSL TEMPORAL_LIGHTS_GLSL R"GLSL(
layout(location = 0) out vec4 o_position;  // xyz world, w = 1 where a surface was seen
layout(location = 1) out vec4 o_normal;
layout(location = 2) out vec4 o_flux;      // reflected (diffuse) flux of this texel, W
uniform float u_metallic;
uniform float u_texel_measure;  // directional: world area of a texel; else solid angle of the centre texel
uniform vec3 u_light_axis;      // view axis of the light's (perspective) camera
void main() {
  vec4 base = base_color();
  vec3 n = facing_normal();
  vec3 flux;
  if (u_light_type[0] == 0) {
    flux = u_light_color[0] * u_texel_measure;  // E * A
  } else {
    vec3 d = v_world - u_light_position[0];
    float dist = length(d);
    vec3 w = d / dist;
    float c = max(dot(w, u_light_axis), 1e-3);
    flux = u_light_color[0] * light_window(0, -w, dist) * u_texel_measure * c * c * c;  // I * solid angle
  }
  o_position = vec4(v_world, 1.0);
  o_normal = vec4(n, 0.0);
  o_flux = vec4(flux * base.rgb * (1.0 - u_metallic), 1.0);
}
)GLSL";

const char* const kFullscreenVertex = R"GLSL(#version 450 core
void main() {
  vec2 p = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
  gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
)GLSL";

static const char* const kDeferredBody = R"GLSL(
layout(binding = 0) uniform sampler2D g_albedo;  // rgb albedo, a metallic
layout(binding = 1) uniform sampler2D g_normal;  // xyz normal, w roughness
layout(binding = 2) uniform sampler2D g_world;   // xyz world, w linear depth (0: background)
layout(binding = 3) uniform sampler2DShadow u_shadow_map;
// Two vec4 per VPL (2000 VPLs = 64000 bytes, inside the 64 KiB uniform-block limit): (position, normal.x),
// (flux, normal.y); the sign of flux.r carries the sign of normal.z (flux is never negative).
layout(std140, binding = 0) uniform Vpls { vec4 vpl_data[2 * MAX_VPLS]; };
layout(location = 0) out vec4 o_direct;  // rgb direct, a shadow
layout(location = 1) out vec4 o_gi;      // rgb gi, a ssao
layout(location = 2) out vec4 o_sum;     // rgb direct * shadow + gi * ssao (shadow * ssao without direct and gi)
uniform vec3 u_camera_pos;
uniform mat4 u_light_vp;       // world -> key light's shadow texture coordinates and depth, [0, 1]
uniform int u_pcf;             // PCF kernel N (N x N taps)
uniform float u_shadow_texel;  // 1 / shadow map size
uniform float u_normal_offset; // world units along the normal before the shadow lookup
uniform int u_ao_dirs;
uniform int u_ao_steps;
uniform float u_ao_radius;     // world units
uniform float u_proj_scale;    // pixels per world unit at depth 1 (P[1][1] * height / 2)
uniform uint u_seed;           // changes every frame (and every reference sample)
uniform int u_vpl_count;
uniform float u_vpl_clamp2;    // minimum squared VPL distance
uniform vec3 u_ambient;        // pi x the environment's radiance (AMBIENT only; renderer.cpp)
uniform vec3 u_fill_irradiance;  // the automatic fill light (FILL only): irradiance facing it
uniform vec3 u_fill_direction;   // the direction it travels (unit)
const float PI = 3.14159265358979;

uint pcg(uint v) {
  uint state = v * 747796405u + 2891336453u;
  uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
  return (word >> 22u) ^ word;
}

float shadow_visibility(vec3 p, vec3 n) {
  vec4 sc = u_light_vp * vec4(p + n * u_normal_offset, 1.0);
  vec3 s = sc.xyz / sc.w;
  if (sc.w <= 0.0 || any(lessThan(s, vec3(0.0))) || any(greaterThan(s, vec3(1.0)))) return 1.0;
  // Reeves et al. 1987 with hardware 2x2 compares: N x N taps one texel apart, centred on the point.
  float half_n = 0.5 * float(u_pcf - 1);
  float sum = 0.0;
  for (int j = 0; j < u_pcf; ++j)
    for (int i = 0; i < u_pcf; ++i)
      sum += texture(u_shadow_map, vec3(s.xy + (vec2(i, j) - half_n) * u_shadow_texel, s.z));
  return sum / float(u_pcf * u_pcf);
}

// Horizon-based ambient occlusion (Bavoil & Sainz 2008): in each of D screen directions (randomly rotated
// per pixel and per frame) march S steps within the projected radius; the horizon is the largest
// elevation sin(h) = dot(v, n) / |v| of a sample above the tangent plane, attenuated by 1 - r^2 / R^2.
// AO = 1 - mean over directions of (sin h - sin(bias)).
float ambient_occlusion(ivec2 p, vec3 P, vec3 n, float depth) {
  float R = u_ao_radius;
  float rpx = R * u_proj_scale / depth;
  if (rpx < 1.0) return 1.0;
  ivec2 size = textureSize(g_world, 0);
  uint h = pcg(uint(p.x) + pcg(uint(p.y) + pcg(u_seed)));
  float rot = float(h & 0xffffu) * (2.0 * PI / 65536.0);
  float off = float(h >> 16u) * (1.0 / 65536.0);
  const float sin_bias = 0.1;
  float occ = 0.0;
  for (int d = 0; d < u_ao_dirs; ++d) {
    float a = rot + 2.0 * PI * float(d) / float(u_ao_dirs);
    vec2 dir = vec2(cos(a), sin(a));
    float horizon = 0.0;
    for (int s = 0; s < u_ao_steps; ++s) {
      float t = (float(s) + off) / float(u_ao_steps);
      vec2 q = vec2(p) + 0.5 + dir * (1.0 + t * (rpx - 1.0));
      ivec2 qi = ivec2(floor(q));
      if (any(lessThan(qi, ivec2(0))) || any(greaterThanEqual(qi, size))) break;
      vec4 w = texelFetch(g_world, qi, 0);
      if (w.w <= 0.0) continue;
      vec3 v = w.xyz - P;
      float l2 = dot(v, v);
      if (l2 > R * R || l2 < 1e-12) continue;
      float e = dot(v, n) * inversesqrt(l2) - sin_bias;
      horizon = max(horizon, e * (1.0 - l2 / (R * R)));
    }
    occ += horizon;
  }
  return clamp(1.0 - occ / float(u_ao_dirs), 0.0, 1.0);
}

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  vec4 wd = texelFetch(g_world, p, 0);
  if (wd.w <= 0.0) {  // background
    o_direct = vec4(0.0, 0.0, 0.0, 1.0);
    o_gi = vec4(0.0, 0.0, 0.0, 1.0);
    o_sum = vec4(0.0);
    return;
  }
  vec4 am = texelFetch(g_albedo, p, 0);
  vec4 nr = texelFetch(g_normal, p, 0);
  vec3 P = wd.xyz;
  vec3 n = normalize(nr.xyz);
  vec3 albedo = am.rgb;
  float metallic = am.a;
  vec3 diffuse = albedo * (1.0 - metallic) / PI;

  vec3 direct = vec3(0.0);
#ifdef TERM_DIRECT
  // Lambert + normalised Blinn-Phong, exponent from roughness (s = 2 / alpha^2 - 2, alpha = roughness^2).
  vec3 V = normalize(u_camera_pos - P);
  float alpha = max(nr.w * nr.w, 1e-3);
  float sh = clamp(2.0 / (alpha * alpha) - 2.0, 1.0, 2048.0);
  vec3 f0 = mix(vec3(0.04), albedo, metallic);
  for (int i = 0; i < u_light_count; ++i) {
    vec3 l;
    vec3 E = light_incident(i, P, l);
    float nl = dot(n, l);
    if (nl <= 0.0) continue;
    vec3 hv = normalize(l + V);
    float spec = (sh + 8.0) / (8.0 * PI) * pow(max(dot(n, hv), 0.0), sh);
    direct += E * nl * (diffuse + f0 * spec);
  }
#endif
  float shadow = 1.0;
#ifdef TERM_SHADOW
  shadow = shadow_visibility(P, n);
#endif
  float ao = 1.0;
#ifdef TERM_SSAO
  ao = ambient_occlusion(p, P, n, wd.w);
#endif
  vec3 gi = vec3(0.0);
#ifdef TERM_GI
  // Instant radiosity without visibility: L = rho/pi * sum_v Phi_v cos(theta_v) cos(theta_x) / (pi d^2).
  vec3 acc = vec3(0.0);
  for (int i = 0; i < u_vpl_count; ++i) {
    vec4 a = vpl_data[2 * i];
    vec4 b = vpl_data[2 * i + 1];
    vec3 vn = vec3(a.w, b.w, sqrt(max(1.0 - a.w * a.w - b.w * b.w, 0.0)));
    if (b.x < 0.0) vn.z = -vn.z;
    vec3 d = a.xyz - P;
    float d2 = dot(d, d);
    vec3 w = d * inversesqrt(max(d2, 1e-12));
    float c = max(dot(n, w), 0.0) * max(-dot(vn, w), 0.0);
    acc += vec3(abs(b.x), b.y, b.z) * (c / max(d2, u_vpl_clamp2));
  }
  gi = diffuse * acc / PI;
#ifdef AMBIENT
  // A uniform environment (USD DomeLight, the rig's ambient) of radiance L: u_ambient = pi L (renderer.cpp), so a
  // Lambertian surface reflects albedo (1 - metallic) L (docs/usd.md).
  gi += diffuse * u_ambient;
#endif
#ifdef FILL
  // The automatic rig's fill light (render.h LightingOptions): unshadowed Lambert, E (n.l)+ of irradiance E.
  gi += diffuse * u_fill_irradiance * max(dot(n, -u_fill_direction), 0.0);
#endif
#endif
  o_direct = vec4(direct, shadow);
  o_gi = vec4(gi, ao);
  // The sum's alpha is 1 on covered pixels (0 on the background): the coverage the dark-frame check counts. It is
  // never written to a file.
#if defined(TERM_DIRECT) || defined(TERM_GI)
  o_sum = vec4(direct * shadow + gi * ao, 1.0);
#else
  // Neither radiance term: the sum is the visibility terms themselves, as grey, so that R,G,B is never an
  // all-zero image that every method reproduces "perfectly" (docs/render-gbuffer.md, Outputs).
  o_sum = vec4(vec3(shadow * ao), 1.0);
#endif
}
)GLSL";

std::string deferred_fragment(bool direct, bool shadow, bool ssao, bool gi, bool ambient, bool fill) {
  std::string s = "#version 450 core\n";
  if (ambient) s += "#define AMBIENT 1\n";
  if (fill) s += "#define FILL 1\n";
  if (direct) s += "#define TERM_DIRECT 1\n";
  if (shadow) s += "#define TERM_SHADOW 1\n";
  if (ssao) s += "#define TERM_SSAO 1\n";
  if (gi) s += "#define TERM_GI 1\n";
  s += "#define MAX_VPLS " + std::to_string(kMaxVpls) + "\n";
  s += TEMPORAL_LIGHTS_GLSL;
  s += kDeferredBody;
  return s;
}

}  // namespace temporal::render_detail
