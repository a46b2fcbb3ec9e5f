// Render options: parsing and printing the values render-gbuffer's command line binds to, and validation.
#include "temporal/render/render.h"

#include "shaders.h"

#include <cmath>
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
  if (options.reference_spp < 1) return Error::usage("--reference-spp must be at least 1");
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
  return {};
}

}  // namespace temporal
