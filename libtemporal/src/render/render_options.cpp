// Render options: parsing and printing the values render-gbuffer's command line binds to, and validation.
#include "temporal/render/render.h"

#include "shaders.h"

#include <cmath>
#include <limits>
#include <sstream>

namespace temporal {

using render_detail::kMaxVpls;

namespace {
std::vector<std::string> split_list(const std::string& list) {
  std::vector<std::string> out;
  std::stringstream ss(list);
  std::string item;
  while (std::getline(ss, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}
}  // namespace

Expected<PayloadOptions> parse_payload_terms(const std::string& list, PayloadOptions base) {
  base.direct = base.shadow = base.ssao = base.gi = false;
  const auto items = split_list(list);
  if (items.empty()) return Error::usage("--payload needs at least one of direct, shadow, ssao, gi");
  for (const auto& t : items) {
    if (t == "direct") base.direct = true;
    else if (t == "shadow") base.shadow = true;
    else if (t == "ssao") base.ssao = true;
    else if (t == "gi") base.gi = true;
    else return Error::usage("unknown payload term '" + t + "': use direct, shadow, ssao, gi");
  }
  return base;
}

std::vector<std::string> PayloadOptions::channels() const {
  std::vector<std::string> c = {"R", "G", "B"};
  if (direct) c.insert(c.end(), {"direct.R", "direct.G", "direct.B"});
  if (shadow) c.push_back("shadow.Y");
  if (ssao) c.push_back("ssao.Y");
  if (gi) c.insert(c.end(), {"gi.R", "gi.G", "gi.B"});
  return c;
}

Expected<RenderOutputs> RenderOutputs::parse(const std::string& list) {
  RenderOutputs o;
  o.gbuffer = o.shade = o.reference = o.color = false;
  const auto items = split_list(list);
  if (items.empty()) return Error::usage("--outputs needs at least one of gbuffer, shade, reference, color");
  for (const auto& t : items) {
    if (t == "gbuffer") o.gbuffer = true;
    else if (t == "shade") o.shade = true;
    else if (t == "reference") o.reference = true;
    else if (t == "color") o.color = true;
    else return Error::usage("unknown output '" + t + "': use gbuffer, shade, reference, color");
  }
  return o;
}

std::string payload_terms_string(const PayloadOptions& p) {
  std::string s;
  for (auto [on, name] : {std::pair{p.direct, "direct"}, {p.shadow, "shadow"}, {p.ssao, "ssao"}, {p.gi, "gi"}})
    if (on) {
      if (!s.empty()) s += ',';
      s += name;
    }
  return s;
}

std::string RenderOutputs::to_string() const {
  std::string s;
  for (auto [on, name] : {std::pair{gbuffer, "gbuffer"}, {shade, "shade"}, {reference, "reference"}, {color, "color"}})
    if (on) {
      if (!s.empty()) s += ',';
      s += name;
    }
  return s;
}

Expected<LightingOptions::Mode> parse_lighting_mode(const std::string& text) {
  if (text == "scene") return LightingOptions::Mode::Scene;
  if (text == "auto") return LightingOptions::Mode::Automatic;
  return Error::usage("--lights '" + text + "' is not one of: scene, auto");
}

const char* to_string(LightingOptions::Mode mode) { return mode == LightingOptions::Mode::Automatic ? "auto" : "scene"; }

Status parse_size(const std::string& text, RenderOptions& options) {
  int w = 0, h = 0;
  char x = 0, extra = 0;
  std::istringstream in(text);
  if (!(in >> w >> x >> h) || (x != 'x' && x != 'X') || (in >> extra) || w < 1 || h < 1)
    return Error::usage("--size '" + text + "' is not WIDTHxHEIGHT (e.g. 1280x1024)");
  options.width = w;
  options.height = h;
  return {};
}

std::string size_string(const RenderOptions& options) {
  return std::to_string(options.width) + "x" + std::to_string(options.height);
}

Status parse_shade_mip_bias(const std::string& text, RenderOptions& options) {
  if (text == "auto") {
    options.shade_mip_bias.reset();
    return {};
  }
  float bias = 0.0f;
  char extra = 0;
  std::istringstream in(text);
  if (!(in >> bias) || (in >> extra)) return Error::usage("--shade-mip-bias '" + text + "' is not a number or 'auto'");
  options.shade_mip_bias = bias;
  return {};
}

std::string shade_mip_bias_string(const RenderOptions& options) {
  if (!options.shade_mip_bias) return "auto";
  std::ostringstream s;
  s << *options.shade_mip_bias;
  return s.str();
}

Status validate(const RenderOptions& options) {
  const PayloadOptions& p = options.payload;
  if (options.width < 1 || options.height < 1 || options.width > 16384 || options.height > 16384)
    return Error::usage("--size must be between 1x1 and 16384x16384");
  if (options.factor < 1 || options.width % options.factor != 0 || options.height % options.factor != 0)
    return Error::usage("--factor " + std::to_string(options.factor) + " must divide the width and height (" +
                        std::to_string(options.width) + "x" + std::to_string(options.height) + ")");
  if (options.reference_spp < 1 || options.reference_spp > kMaxReferenceSpp)
    return Error::usage("--reference-spp must be between 1 and " + std::to_string(kMaxReferenceSpp));
  if (options.reference_jitter != JitterMode::Halton && options.reference_jitter != JitterMode::None)
    return Error::usage(std::string("--reference-jitter ") + to_string(options.reference_jitter) +
                        " is not a reference pattern: use halton (supersampled) or none (pixel centres, noise averaged)");
  if (options.shade_mip_bias && !(std::abs(*options.shade_mip_bias) <= 16.0f))
    return Error::usage("--shade-mip-bias must be a number between -16 and 16 (or 'auto')");
  if (p.pcf_kernel < 1 || p.pcf_kernel > 32) return Error::usage("--pcf must be between 1 and 32");
  if (p.shadow_map_size < 16 || p.shadow_map_size > 8192) return Error::usage("--shadow-map-size must be in 16..8192");
  if (p.ssao_directions < 1 || p.ssao_steps < 1) return Error::usage("--ssao-directions and --ssao-steps must be >= 1");
  if (p.vpl_count < 1 || p.vpl_count > kMaxVpls)
    return Error::usage("--vpls must be between 1 and " + std::to_string(kMaxVpls));
  if (p.rsm_size < 4 || p.rsm_size > 2048) return Error::usage("--rsm-size must be in 4..2048");
  const LightingOptions& l = options.lighting;
  for (auto [v, flag] : {std::pair{l.key, "--key-light"}, {l.fill, "--fill-light"}, {l.ambient, "--ambient"}})
    if (!(v >= 0.0f && v <= 100.0f)) return Error::usage(std::string(flag) + " must be between 0 and 100");
  return {};
}

RenderText::RenderText(const RenderOptions& d)
    : size(size_string(d)), payload(payload_terms_string(d.payload)), outputs(d.outputs.to_string()),
      jitter(to_string(d.color_jitter)), shade_jitter(to_string(d.shade_jitter)),
      reference_jitter(to_string(d.reference_jitter)), shade_mip_bias(shade_mip_bias_string(d)), gl(to_string(d.gl)),
      lights(to_string(d.lighting.mode)), seed(double(d.seed)) {}

ParamList render_params(RenderOptions& o, RenderText& t) {
  PayloadOptions& p = o.payload;
  LightingOptions& l = o.lighting;
  const int most = std::numeric_limits<int>::max();
  const std::vector<std::string> jitters = {"regular", "regular-raster", "halton", "random", "none"};
  Param seed{"--seed", "Seed of random jitter, SSAO patterns and VPL sets", &t.seed, 0.0, 4294967295.0};
  return {
      Param::text("--size", "Full resolution WIDTHxHEIGHT", &t.size),
      Param::text("--payload", "Payload terms: any of direct,shadow,ssao,gi", &t.payload),
      Param::integer("--factor", "Low-resolution factor k: shade is width/k x height/k", &o.factor, 1, 16384),
      Param::choice("--jitter", "Colour jitter", &t.jitter, jitters),
      Param::choice("--shade-jitter",
                    "Shade jitter: regular (k x k pattern, dispersed order), regular-raster (raster order), halton, "
                    "random, none",
                    &t.shade_jitter, jitters),
      Param::integer("--reference-spp", "Reference samples per pixel (the reference costs about spp renders a frame)",
                     &o.reference_spp, 1, kMaxReferenceSpp),
      Param::choice("--reference-jitter",
                    "Reference sample positions: halton (supersampled) | none (pixel centres: the colour with its "
                    "SSAO/VPL noise averaged)",
                    &t.reference_jitter, {"halton", "none"}),
      Param::text("--outputs", "Outputs: any of gbuffer,shade,reference,color", &t.outputs),
      Param::integer("--pcf", "Shadow PCF kernel N (N x N shadow-map texels)", &p.pcf_kernel, 1, 32),
      Param::integer("--shadow-map-size", "Shadow map texels per side", &p.shadow_map_size, 16, 8192),
      // Finite ranges (issue 26): the offset is bias x texel size in world units, the radius is projected to pixels
      // and squared in the shader (float), so both stay far from overflow.
      Param::real("--shadow-bias", "Shadow normal offset in shadow-map texels", &p.shadow_bias, -64.0, 64.0),
      Param::integer("--ssao-directions", "SSAO horizon directions", &p.ssao_directions, 1, most),
      Param::integer("--ssao-steps", "SSAO steps per direction", &p.ssao_steps, 1, most),
      Param::real("--ssao-radius", "SSAO radius in world units; 0: 5% of the scene diagonal", &p.ssao_radius, 0.0, 1e6),
      Param::integer("--vpls", "Virtual point lights for gi", &p.vpl_count, 1, kMaxVpls),
      Param::integer("--rsm-size", "Reflective shadow map texels per side (VPL candidates)", &p.rsm_size, 4, 2048),
      Param::flag_off("--no-mipmaps", "Sample textures without mipmaps (severe undersampling)", &o.mipmaps),
      Param::text("--shade-mip-bias", "Texture LOD bias of the low-res payload; auto: -log2(K), the full-res mip level",
                  &t.shade_mip_bias),
      Param::choice("--lights",
                    "scene: the scene's lights, the automatic key/fill/ambient rig only for a scene without lights; "
                    "auto: the rig for every scene",
                    &t.lights, {"scene", "auto"}),
      Param::real("--key-light", "Automatic key light: radiance a white surface facing it reflects (1: irradiance pi)",
                  &l.key, 0.0, 100.0),
      Param::real("--fill-light", "Automatic fill light (unshadowed, part of gi), same unit", &l.fill, 0.0, 100.0),
      Param::real("--ambient", "Automatic ambient radiance (part of gi, times ssao)", &l.ambient, 0.0, 100.0),
      seed,
      Param::choice("--gl",
                    "OpenGL context: osmesa (llvmpipe in the process), egl (EGL device platform: a GPU, or Mesa's "
                    "software device), auto (a GPU through EGL when one exists, else osmesa)",
                    &t.gl, {"osmesa", "egl", "auto"}),
      Param::integer("--gl-device", "EGL device index (--list-gl-devices); -1: the first GPU, else the first device",
                     &o.gl_device, -1, most),
  };
}

Status apply_render_text(const RenderText& t, RenderOptions& r) {
  if (auto s = parse_size(t.size, r); !s) return s;
  auto payload = parse_payload_terms(t.payload, r.payload);
  if (!payload) return payload.error();
  r.payload = *payload;
  auto outputs = RenderOutputs::parse(t.outputs);
  if (!outputs) return outputs.error();
  r.outputs = *outputs;
  auto color = parse_jitter_mode(t.jitter);
  if (!color) return color.error();
  auto shade = parse_jitter_mode(t.shade_jitter);
  if (!shade) return shade.error();
  auto reference = parse_jitter_mode(t.reference_jitter);
  if (!reference) return reference.error();
  r.color_jitter = *color;
  r.shade_jitter = *shade;
  r.reference_jitter = *reference;
  if (auto s = parse_shade_mip_bias(t.shade_mip_bias, r); !s) return s;
  auto gl = parse_gl_api(t.gl);
  if (!gl) return gl.error();
  r.gl = *gl;
  auto lights = parse_lighting_mode(t.lights);
  if (!lights) return lights.error();
  r.lighting.mode = *lights;
  if (t.seed != std::floor(t.seed)) return Error::usage("--seed must be a whole number in [0, 4294967295]");
  r.seed = std::uint32_t(t.seed);
  return validate(r);
}

}  // namespace temporal
