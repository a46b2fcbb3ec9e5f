// The UD-factored RLS step (temporal/phlm/rls.h) against seed 003 eq. 6-7 evaluated directly in double precision.
#include "temporal/phlm/rls.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace {

using namespace temporal;
using namespace temporal::phlm;

// Direct eq. 6-7 on a full double matrix.
void direct_step(double P[4][4], double beta[3][4], const double x[4], const double y[3], double lambda) {
  double px[4] = {}, xpx = 0.0;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) px[i] += P[i][j] * x[j];
  for (int i = 0; i < 4; ++i) xpx += x[i] * px[i];
  double q[4];
  for (int i = 0; i < 4; ++i) q[i] = px[i] / (lambda + xpx);
  for (int c = 0; c < 3; ++c) {
    double pred = 0.0;
    for (int k = 0; k < 4; ++k) pred += beta[c][k] * x[k];
    const double e = y[c] - pred;
    for (int k = 0; k < 4; ++k) beta[c][k] += q[k] * e;
  }
  double xp[4] = {};  // x^T P (P symmetric: = px)
  for (int j = 0; j < 4; ++j) xp[j] = px[j];
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) P[i][j] = (P[i][j] - q[i] * xp[j]) / lambda;
}

TEST(Rls, IndexPacking) {
  EXPECT_EQ(rls::off_index<4>(0, 1), 0);
  EXPECT_EQ(rls::off_index<4>(0, 3), 2);
  EXPECT_EQ(rls::off_index<4>(1, 2), 3);
  EXPECT_EQ(rls::off_index<4>(2, 3), 5);
  EXPECT_EQ(rls::packed_index<4>(0, 0), 0);
  EXPECT_EQ(rls::packed_index<4>(1, 1), 4);
  EXPECT_EQ(rls::packed_index<4>(3, 3), 9);
  EXPECT_EQ(rls::kOffDiagonal<4> + 4, 10);  // P in 10 floats for d = 4
  EXPECT_EQ(rls::kOffDiagonal<2> + 2, 3);   // and 3 for d = 2
}

TEST(Rls, UdUpdateMatchesEquations6And7) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  const double lambda = 0.998;
  rls::Model<4, 3> m;
  const float y0[3] = {0.3f, 0.5f, 0.7f};
  rls::reset(m, y0, 1000.0f);
  double P[4][4] = {}, beta[3][4] = {};
  for (int i = 0; i < 4; ++i) P[i][i] = 1000.0;
  for (int c = 0; c < 3; ++c) beta[c][0] = y0[c];
  for (int t = 0; t < 200; ++t) {
    double xd[4] = {1.0, uni(rng), uni(rng), uni(rng)}, yd[3] = {uni(rng), uni(rng), uni(rng)};
    float xf[4], yf[3];
    for (int k = 0; k < 4; ++k) xf[k] = float(xd[k]);
    for (int c = 0; c < 3; ++c) yf[c] = float(yd[c]);
    for (int k = 0; k < 4; ++k) xd[k] = xf[k];
    for (int c = 0; c < 3; ++c) yd[c] = yf[c];
    direct_step(P, beta, xd, yd, lambda);
    rls::update(m, xf, yf, float(lambda), 1e30f, 1e30f);  // no bounds: must equal the plain equations
  }
  float p[10];
  rls::covariance<4>(m.u, m.d, p);
  for (int i = 0; i < 4; ++i)
    for (int j = i; j < 4; ++j) {
      const double ref = P[i][j];
      EXPECT_NEAR(p[rls::packed_index<4>(i, j)], ref, 1e-3 * std::fabs(ref) + 1e-4) << i << "," << j;
      EXPECT_NEAR(P[i][j], P[j][i], 1e-9 * std::fabs(P[i][j]) + 1e-12);
    }
  for (int c = 0; c < 3; ++c)
    for (int k = 0; k < 4; ++k) EXPECT_NEAR(m.beta[c][k], beta[c][k], 2e-3) << c << "," << k;
}

TEST(Rls, WindUpIsBoundedAndPStaysPositiveDefinite) {
  // A constant predictor excites one direction only; without bounds P would grow as 1000 / 0.998^t.
  rls::Model<4, 3> m;
  const float y[3] = {0.5f, 0.5f, 0.5f};
  rls::reset(m, y, 1000.0f);
  const float x[4] = {1.0f, 0.5f, 0.5f, 0.5f};
  float t = 0.0f;
  for (int i = 0; i < 20000; ++i) t = rls::update(m, x, y, 0.998f, 1000.0f, 16000.0f);
  EXPECT_TRUE(std::isfinite(t));
  EXPECT_LE(t, 16000.0f);
  for (float d : m.d) {
    EXPECT_GT(d, 0.0f);
    EXPECT_LE(d, 1000.0f);
  }
  // The excited direction keeps forgetting: its gain x^T P x / (lambda + x^T P x) stays near 1 - lambda
  // (an effective memory of ~500 frames), it does not collapse to 0.
  float p[10];
  rls::covariance<4>(m.u, m.d, p);
  double xpx = 0.0;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) xpx += x[i] * p[rls::packed_index<4>(std::min(i, j), std::max(i, j))] * x[j];
  const double gain = xpx / (0.998 + xpx);
  EXPECT_NEAR(gain, 0.002, 0.001);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(rls::predict(m, c, x), 0.5f, 1e-5f);
}

}  // namespace
