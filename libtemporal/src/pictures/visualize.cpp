// Heat maps, colour bars and G-buffer pictures (temporal/pictures/visualize.h).
#include "temporal/pictures/visualize.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

namespace temporal {
namespace {

std::string tick_text(float v) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", double(v));
  return text;
}

std::uint8_t code(float v) { return std::uint8_t(std::lround(255.0f * std::clamp(v, 0.0f, 1.0f))); }

}  // namespace

Picture heat_map(const float* values, const float* invalid, int width, int height, Colormap map, float low, float high) {
  Picture p(width, height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const std::size_t i = std::size_t(y) * std::size_t(width) + std::size_t(x);
      p.at(x, y) = invalid && invalid[i] > 0.5f ? kInvalidColor
                   : std::isinf(values[i])       ? kNonFiniteColor
                                                 : colormap_color(map, values[i], low, high);
    }
  return p;
}

Expected<Picture> colour_bar(Colormap map, float low, float high, const std::string& label, int width, const Font& font) {
  const int size = width >= 240 ? 13 : 10;
  const int margin = std::max(4, font.text_width(tick_text(high), size) / 2 + 2);
  const int ramp_w = std::max(8, width - 2 * margin), ramp_h = size + 2, tick = 4;
  const int height = 4 + ramp_h + tick + 2 * Font::line_height(size) + 2;
  Picture p(width, height);
  const int top = 4;
  for (int x = 0; x < ramp_w; ++x) {
    const float t = ramp_w > 1 ? float(x) / float(ramp_w - 1) : 0.0f;
    p.fill({margin + x, top, 1, ramp_h}, colormap_color(map, low + t * (high - low), low, high));
  }
  p.outline({margin - 1, top - 1, ramp_w + 2, ramp_h + 2}, {64, 64, 64});
  for (int k = 0; k <= 2; ++k) {
    const int x = margin + k * (ramp_w - 1) / 2;
    p.fill({x, top + ramp_h + 1, 1, tick}, kBlack);
    const std::string t = tick_text(low + 0.5f * float(k) * (high - low));
    const int tw = font.text_width(t, size);
    if (auto st = font.draw(p, std::clamp(x - tw / 2, 0, std::max(0, width - tw)), top + ramp_h + tick + 1, t, size, kBlack); !st)
      return st.error();
  }
  const int lw = font.text_width(label, size);
  if (auto st = font.draw(p, std::max(0, (width - lw) / 2), top + ramp_h + tick + 1 + Font::line_height(size), label, size,
                          kBlack);
      !st)
    return st.error();
  return p;
}

Picture stacked(const Picture& picture, const Picture& bar) {
  Picture p(std::max(picture.width(), bar.width()), picture.height() + bar.height());
  p.paste(picture, 0, 0);
  p.paste(bar, 0, picture.height());
  return p;
}

float nice_ceiling(float v) {
  if (!(v > 0.0f) || !std::isfinite(v)) return 1.0f;
  // In double, from the decade's exponent, so that 10^k comes out as the float nearest 10^k (0.1f, not 0.099999994f).
  const double e = std::floor(std::log10(double(v)));
  for (double m : {1.0, 2.0, 2.5, 5.0})
    if (float(m * std::pow(10.0, e)) >= v) return float(m * std::pow(10.0, e));
  return float(std::pow(10.0, e + 1.0));
}

float plane_quantile(const float* values, std::size_t count, double q) {
  std::vector<float> v;
  v.reserve(count);
  for (std::size_t i = 0; i < count; ++i)
    if (std::isfinite(values[i])) v.push_back(values[i]);
  if (v.empty()) return 0.0f;
  const std::size_t k = std::min(v.size() - 1, std::size_t(std::clamp(q, 0.0, 1.0) * double(v.size() - 1) + 0.5));
  std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(k), v.end());
  return v[k];
}

Picture depth_picture(const float* z, int width, int height, float far_clip) {
  const std::size_t n = std::size_t(width) * std::size_t(height);
  auto foreground = [&](float d) { return std::isfinite(d) && d > 0.0f && (far_clip <= 0.0f || d < 0.999f * far_clip); };
  float near = std::numeric_limits<float>::infinity(), far = 0.0f;
  for (std::size_t i = 0; i < n; ++i)
    if (foreground(z[i])) {
      near = std::min(near, z[i]);
      far = std::max(far, z[i]);
    }
  Picture p(width, height, kBlack);
  if (!(far > 0.0f)) return p;
  const float inv_near = 1.0f / near, inv_far = 1.0f / far;
  const float span = inv_near > inv_far ? inv_near - inv_far : 1.0f;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const float d = z[std::size_t(y) * std::size_t(width) + std::size_t(x)];
      if (!foreground(d)) continue;
      // Far foreground keeps a little brightness (0.15), so it stays apart from the black background.
      const std::uint8_t g = code(0.15f + 0.85f * (1.0f / d - inv_far) / span);
      p.at(x, y) = {g, g, g};
    }
  return p;
}

Picture normal_picture(const float* nx, const float* ny, const float* nz, int width, int height) {
  Picture p(width, height, kBlack);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const std::size_t i = std::size_t(y) * std::size_t(width) + std::size_t(x);
      const float len2 = nx[i] * nx[i] + ny[i] * ny[i] + nz[i] * nz[i];
      if (!(len2 >= 0.25f) || !std::isfinite(len2)) continue;
      p.at(x, y) = {code(0.5f * (nx[i] + 1.0f)), code(0.5f * (ny[i] + 1.0f)), code(0.5f * (nz[i] + 1.0f))};
    }
  return p;
}

Rgb8 hsv_color(float h, float s, float v) {
  h = std::fmod(h, 360.0f);
  if (h < 0.0f) h += 360.0f;
  const float c = v * s, hp = h / 60.0f, x = c * (1.0f - std::fabs(std::fmod(hp, 2.0f) - 1.0f)), m = v - c;
  float r = 0, g = 0, b = 0;
  if (hp < 1) r = c, g = x;
  else if (hp < 2) r = x, g = c;
  else if (hp < 3) g = c, b = x;
  else if (hp < 4) g = x, b = c;
  else if (hp < 5) r = x, b = c;
  else r = c, b = x;
  return {code(r + m), code(g + m), code(b + m)};
}

Picture motion_picture(const float* mx, const float* my, int width, int height, float full_scale, float* used_scale) {
  const std::size_t n = std::size_t(width) * std::size_t(height);
  if (!(full_scale > 0.0f)) {
    std::vector<float> len(n);
    for (std::size_t i = 0; i < n; ++i) len[i] = std::hypot(mx[i], my[i]);
    full_scale = std::max(1.0f, plane_quantile(len.data(), n, 0.99));
  }
  if (used_scale) *used_scale = full_scale;
  Picture p(width, height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const std::size_t i = std::size_t(y) * std::size_t(width) + std::size_t(x);
      if (!std::isfinite(mx[i]) || !std::isfinite(my[i])) {
        p.at(x, y) = kNonFiniteColor;
        continue;
      }
      // Image y points down: flip it so that hue angles are counter-clockwise as seen on the screen.
      const float angle = std::atan2(-my[i], mx[i]) * 180.0f / 3.14159265f;
      p.at(x, y) = hsv_color(angle, std::min(1.0f, std::hypot(mx[i], my[i]) / full_scale), 1.0f);
    }
  return p;
}

Picture id_picture(const std::uint32_t* id, int width, int height) {
  Picture p(width, height, kBlack);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const std::uint32_t v = id[std::size_t(y) * std::size_t(width) + std::size_t(x)];
      if (v == 0) continue;
      const float hue = std::fmod(float(v) * 137.50776f, 360.0f);  // the golden angle: neighbours far apart
      p.at(x, y) = hsv_color(hue, 0.55f + 0.3f * float(v % 2), 0.95f - 0.25f * float((v / 2) % 2));
    }
  return p;
}

}  // namespace temporal
