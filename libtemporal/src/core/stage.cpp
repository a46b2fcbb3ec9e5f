// The stage types' checks (temporal/core/stage.h).
#include "temporal/core/stage.h"

#include <algorithm>
#include <cmath>

namespace temporal {
namespace {

std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) {
    if (!s.empty()) s += ", ";
    s += x;
  }
  return s.empty() ? std::string("(none)") : s;
}

}  // namespace

// The channels a layer name stands for in a G-buffer.
std::vector<std::string> layer_channel_names(const std::string& layer) {
  if (layer == "depth") return {"depth.Z"};
  if (layer == "prevDepth") return {"prevDepth.Z"};
  if (layer == "N") return {"N.X", "N.Y", "N.Z"};
  if (layer == "motion") return {"motion.X", "motion.Y"};
  if (layer == "albedo") return {"albedo.R", "albedo.G", "albedo.B"};
  if (layer == "id") return {"id"};
  return {};
}

Status check_gbuffer_layers(const Image& g, const std::vector<LayerNeed>& needs, const std::string& path) {
  for (const auto& need : needs) {
    if (!need.required) continue;
    bool ok = true;
    for (const auto& c : layer_channel_names(need.layer))
      ok = ok && (c == "id" ? g.uint_plane(c) != nullptr : g.plane(c) != nullptr);
    if (layer_channel_names(need.layer).empty()) ok = !g.layer_channels(need.layer).empty();
    if (!ok) {
      std::string how = "; render the G-buffer with render-gbuffer --outputs gbuffer";
      if (need.layer == "id" && g.has_channel("id")) how = "; `id` must be stored as uint32 (render-gbuffer writes it so)";
      if (!need.alternative.empty()) how += " (" + need.alternative + ")";
      return Error::input(path, "no layer '" + need.layer + "' (have: " + join(g.channel_names()) + ")" + how);
    }
  }
  return Status::ok();
}

std::size_t count_non_finite_layers(const Image& image, const std::vector<std::string>& layers, float max_magnitude) {
  std::vector<const float*> planes;
  for (const auto& name : image.channel_names()) {
    bool selected = layers.empty();
    for (const auto& l : layers) {
      const auto channels = layer_channel_names(l);
      selected = selected || name == l || std::find(channels.begin(), channels.end(), name) != channels.end() ||
                 name.rfind(l + ".", 0) == 0 || (l == "rgb" && (name == "R" || name == "G" || name == "B"));
    }
    if (const float* p = selected ? image.plane(name) : nullptr) planes.push_back(p);
  }
  std::size_t n = 0;
  for (std::size_t i = 0; i < image.pixel_count(); ++i) {
    bool finite = true;
    for (const float* p : planes) finite = finite && std::isfinite(p[i]) && std::abs(p[i]) <= max_magnitude;
    n += finite ? 0 : 1;
  }
  return n;
}

}  // namespace temporal
