// Colour maths: scene-linear Rec.709 is the working space of every tool. Per-pixel inner loops use the inline
// functions below; their matrices are the ones registered in the built-in OpenColorIO config
// (temporal/io/color_config.h), and a test checks that the two agree. No colour library is needed here.
#pragma once

namespace temporal {

// Rec.709 / sRGB primaries luminance (ITU-R BT.709), on linear values.
inline float luminance(float r, float g, float b) { return 0.2126f * r + 0.7152f * g + 0.0722f * b; }

// YCgCo (Malvar & Sullivan 2003): Y = R/4 + G/2 + B/4, Cg = -R/4 + G/2 - B/4, Co = R/2 - B/2.
// Exactly invertible: R = Y - Cg + Co, G = Y + Cg, B = Y - Cg - Co.
inline void rgb_to_ycgco(float r, float g, float b, float& y, float& cg, float& co) {
  y = 0.25f * r + 0.5f * g + 0.25f * b;
  cg = -0.25f * r + 0.5f * g - 0.25f * b;
  co = 0.5f * r - 0.5f * b;
}
inline void ycgco_to_rgb(float y, float cg, float co, float& r, float& g, float& b) {
  const float t = y - cg;
  r = t + co;
  g = y + cg;
  b = t - co;
}

// The space the temporal methods clip their histories in, against the box of a 3x3 neighbourhood (Karis 2014: a
// tighter box around chroma; FSR 2 RectifyHistory): each R,G,B triple of a pixel's `channels` values as YCgCo, the
// channels left over (a one-channel payload such as ssao.Y, a fourth channel) as they are. `in` and `out` may be the
// same array. Used by phlm's box test, taa's clipping and taau's rectification.
inline void to_ycgco_box(const float* in, float* out, int channels) {
  int c = 0;
  for (; c + 3 <= channels; c += 3) rgb_to_ycgco(in[c], in[c + 1], in[c + 2], out[c], out[c + 1], out[c + 2]);
  for (; c < channels; ++c) out[c] = in[c];
}
inline void from_ycgco_box(const float* in, float* out, int channels) {
  int c = 0;
  for (; c + 3 <= channels; c += 3) ycgco_to_rgb(in[c], in[c + 1], in[c + 2], out[c], out[c + 1], out[c + 2]);
  for (; c < channels; ++c) out[c] = in[c];
}

}  // namespace temporal
