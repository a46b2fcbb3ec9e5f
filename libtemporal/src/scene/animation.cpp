// Animation sampler evaluation, glTF 2.0 section 3.11 and Appendix C ("Interpolation").
#include "scene_description.h"

#include <algorithm>
#include <cmath>

namespace temporal::scene_detail {
namespace {

void normalise4(float* q) {
  const float n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (n > 0.0f) {
    for (int i = 0; i < 4; ++i) q[i] /= n;
  } else {
    q[0] = q[1] = q[2] = 0.0f;
    q[3] = 1.0f;
  }
}

// Spherical linear interpolation along the shortest arc (Appendix C: the sign of the dot product flips b).
void slerp(const float* a, const float* b, float s, float* out) {
  float d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3];
  const float sign = d < 0.0f ? -1.0f : 1.0f;
  d = std::fabs(d);
  float wa, wb;
  if (d > 0.9995f) {  // nearly parallel: linear interpolation, normalised below, avoids 0/0
    wa = 1.0f - s;
    wb = s;
  } else {
    const float theta = std::acos(d);
    const float sin_theta = std::sin(theta);
    wa = std::sin((1.0f - s) * theta) / sin_theta;
    wb = std::sin(s * theta) / sin_theta;
  }
  for (int i = 0; i < 4; ++i) out[i] = wa * a[i] + sign * wb * b[i];
  normalise4(out);
}

// Hermite spline of Appendix C: p(s) = (2s^3 - 3s^2 + 1) v_k + td (s^3 - 2s^2 + s) b_k
//                                  + (-2s^3 + 3s^2) v_k+1 + td (s^3 - s^2) a_k+1,
// b_k the out-tangent of key k, a_k+1 the in-tangent of key k+1, both scaled by the key spacing td.
// Compiled without FMA contraction so that the value does not depend on the CPU (-march=native) and equals
// what the scene generator bakes into the USD copies of the built-in scenes (assets/generator).
__attribute__((optimize("fp-contract=off"))) void hermite(const float* v0, const float* b0, const float* v1,
                                                           const float* a1, float s, float td, int c, float* out) {
  const float s2 = s * s, s3 = s2 * s;
  const float h00 = 2 * s3 - 3 * s2 + 1, h10 = s3 - 2 * s2 + s, h01 = -2 * s3 + 3 * s2, h11 = s3 - s2;
  for (int i = 0; i < c; ++i) out[i] = h00 * v0[i] + h10 * td * b0[i] + h01 * v1[i] + h11 * td * a1[i];
}

}  // namespace

void sample(const Sampler& sampler, float t, bool rotation, float* out) {
  const int c = sampler.components;
  const auto& times = sampler.times;
  const std::size_t n = times.size();
  const bool cubic = sampler.interpolation == Interpolation::CubicSpline;
  // CUBICSPLINE stores (in-tangent, value, out-tangent) per key: the value of key k starts at (3k+1)*c.
  auto value = [&](std::size_t k) -> const float* {
    return sampler.values.data() + (cubic ? (3 * k + 1) * c : k * c);
  };
  if (n == 0) return;
  if (n == 1 || t <= times.front()) {
    std::copy_n(value(0), c, out);
  } else if (t >= times.back()) {
    std::copy_n(value(n - 1), c, out);
  } else {
    // First key strictly after t; t lies in [times[k], times[k+1]).
    const std::size_t k1 = static_cast<std::size_t>(std::upper_bound(times.begin(), times.end(), t) - times.begin());
    const std::size_t k = k1 - 1;
    const float td = times[k1] - times[k];
    const float s = (t - times[k]) / td;
    switch (sampler.interpolation) {
      case Interpolation::Step:
        std::copy_n(value(k), c, out);
        break;
      case Interpolation::Linear:
        if (rotation) {
          slerp(value(k), value(k1), s, out);
        } else {
          const float* a = value(k);
          const float* b = value(k1);
          for (int i = 0; i < c; ++i) out[i] = a[i] + s * (b[i] - a[i]);
        }
        break;
      case Interpolation::CubicSpline: {
        const float* v0 = value(k);
        const float* v1 = value(k1);
        hermite(v0, v0 + c, v1, v1 - c, s, td, c, out);  // out-tangent of k, in-tangent of k+1
        break;
      }
    }
  }
  if (rotation) normalise4(out);
}

}  // namespace temporal::scene_detail
