// GLSL 4.50 sources of the renderer's passes (docs/render-gbuffer.md has the equations).
#pragma once

#include <string>

namespace temporal::render_detail {

// Shared vertex shader of every geometry pass (G-buffer, shadow map, reflective shadow map).
extern const char* const kGeometryVertex;
// G-buffer: albedo+metallic, normal+roughness, motion, world position+linear depth, id.
extern const char* const kGbufferFragment;
// Shadow map: depth only (the fragment shader only applies alpha-mask cut-outs).
extern const char* const kShadowFragment;
// Reflective shadow map: world position, normal, reflected flux per texel.
extern const char* const kRsmFragment;
// Full-screen triangle.
extern const char* const kFullscreenVertex;
// Deferred payload shading; `defines` switches terms on (TERM_DIRECT, TERM_SHADOW, TERM_SSAO, TERM_GI) and the
// ambient of a uniform environment into gi (AMBIENT: only compiled for scenes that have one, so that other
// scenes run exactly the shader they always ran) and the automatic rig's fill light into gi (FILL: only for scenes
// lit by the rig, render.h LightingOptions).
std::string deferred_fragment(bool direct, bool shadow, bool ssao, bool gi, bool ambient, bool fill);

inline constexpr int kMaxLights = 8;
// VPLs live in a uniform block of two vec4 each: 64 KiB / 32 bytes, rounded down.
inline constexpr int kMaxVpls = 2000;

}  // namespace temporal::render_detail
