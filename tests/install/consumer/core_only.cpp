// The smallest use of the core component: an image, its PSNR against itself plus noise.
#include "temporal/core/image.h"
#include "temporal/metrics/metrics.h"

#include <cmath>
#include <cstdint>
#include <cstdio>

int main() {
  temporal::Image a(8, 8), b(8, 8);
  float* pa = a.add_channel("Y", 0.5f);
  float* pb = b.add_channel("Y", 0.5f);
  pb[3] = 0.6f;  // one pixel off by 0.1: MSE = 0.01 / 64
  const float* ta[] = {pb};
  const float* ra[] = {pa};
  std::uint8_t valid[64];
  temporal::finite_mask(ta, ra, 64, valid);
  const auto se = temporal::squared_error(ta, ra, 8, 8, valid, nullptr);
  const double psnr = temporal::psnr_db(se.all, 1.0);
  std::printf("psnr %.4f dB\n", psnr);
  return std::abs(psnr - 10.0 * std::log10(64.0 / 0.01)) < 1e-3 ? 0 : 1;
}
