// Recursive least squares with a forgetting factor, in UD-factored form, with a bounded covariance.
//
// Seed 003 (Iglesias-Guitian et al. 2016), eq. 6-7: for a linear model f = beta^T x with predictor x in R^N
// and C outputs sharing x (beta is C x N, one row per colour channel), each new sample y updates
//   Q    = P x / (lambda + x^T P x)                      (gain, eq. 6)
//   beta = beta + Q e^T,  e = y - beta^T x               (eq. 6, e is the a-priori error of eq. 5)
//   P    = (P - Q x^T P) / lambda                        (eq. 7)
// P is the "inverse covariance" of the paper's Table 1 (the inverse of the weighted Gram matrix of x).
//
// Storage: P is symmetric positive definite and is kept as P = U D U^T (Bierman 1977), U unit upper
// triangular, D diagonal: N (N - 1) / 2 + N values, i.e. 10 floats for N = 4 and 3 for N = 2, the same count
// as the packed upper triangle of a symmetric P. The factored update is the textbook cure for the float32
// failure of eq. 7 (loss of symmetry and positive definiteness by cancellation): D stays > 0 and
// U D U^T is symmetric by construction, and the factors carry P's wide eigenvalue range (1e-3 along an
// excited direction, 1e3 along an idle one) without the rounding that a packed float P suffers.
//
// Wind-up: where x stops varying, eq. 7 multiplies P by 1/lambda every frame along the directions that x
// no longer excites (1000 * 1.002^20000 ~ 1e20 after 20,000 frames at lambda = 0.998). `update` caps every
// D entry at `d_max` (the filters use the initial P0): the idle directions stop growing at the value a freshly
// reset model has, while an excited direction (small D) keeps its exponential forgetting and so its ability to
// track. As a second guard, when trace(P) still exceeds `trace_max` (U can grow where features are large),
// all of D is scaled down. Both keep P symmetric positive definite.
#pragma once

#include "temporal/core/minmax.h"

#include <cmath>

namespace temporal::phlm::rls {

// The per-pixel steps (reset, predict, trace, bierman_update, update) are always inlined: phlm's kernel is compiled
// once per instruction set (temporal/core/isa.h), and with three callers GCC's inliner left bierman_update out of
// line, compiled for the baseline (SSE, no FMA), in every copy. Their operations are unchanged.
//
// Model, reset, predict, trace and bierman_update take the value type T: float for one model, or a GCC vector of
// floats for one model per lane (phlm_kernels.inc runs Algorithm 1 for 4 to 8 pixels at once, one per lane). The
// operations are the same in the same order for either; they have no branches, so every lane computes exactly
// what the float version computes for its pixel.

// Number of strictly-upper entries of an N x N unit upper triangular U.
template <int N>
inline constexpr int kOffDiagonal = N * (N - 1) / 2;
// Number of values of the packed upper triangle of a symmetric N x N matrix.
template <int N>
inline constexpr int kPacked = N * (N + 1) / 2;

// Position of U(i, j), i < j, in the packed strictly-upper array (row-major: U01 U02 U03 U12 U13 U23).
template <int N>
constexpr int off_index(int i, int j) {
  return i * N - i * (i + 1) / 2 + (j - i - 1);
}
// Position of P(i, j), i <= j, in a packed upper triangle (row-major: P00 P01 P02 P03 P11 P12 ...).
template <int N>
constexpr int packed_index(int i, int j) {
  return i * N - i * (i - 1) / 2 + (j - i);
}

// One linear model: C outputs, N predictors.
template <int N, int C, typename T = float>
struct Model {
  T beta[C][N];
  T u[kOffDiagonal<N> > 0 ? kOffDiagonal<N> : 1];
  T d[N];
};

// Seed 003 section 6, "Initialization": the intercept coefficients take `value`, the slopes are cleared,
// P = p0 * I (U = I, D = p0).
template <int N, int C, typename T>
[[gnu::always_inline]] inline void reset(Model<N, C, T>& m, const T value[C], float p0) {
  for (int c = 0; c < C; ++c) {
    m.beta[c][0] = value[c];
    for (int k = 1; k < N; ++k) m.beta[c][k] = T{};
  }
  for (int k = 0; k < kOffDiagonal<N>; ++k) m.u[k] = T{};
  for (int k = 0; k < N; ++k) m.d[k] = T{} + p0;
}

// Prediction of output c: beta_c^T x (eq. 4 / 8).
template <int N, int C, typename T>
[[gnu::always_inline]] inline T predict(const Model<N, C, T>& m, int c, const T x[N]) {
  T s = T{};
  for (int k = 0; k < N; ++k) s += m.beta[c][k] * x[k];
  return s;
}

// trace(P) = sum_j D_j (1 + sum_{i<j} U_ij^2).
template <int N, typename T>
[[gnu::always_inline]] inline T trace(const T* u, const T* d) {
  T t = T{};
  for (int j = 0; j < N; ++j) {
    T col = T{} + 1.0f;
    for (int i = 0; i < j; ++i) col += u[off_index<N>(i, j)] * u[off_index<N>(i, j)];
    t += d[j] * col;
  }
  return t;
}

// P = U D U^T as a packed upper triangle (kPacked<N> values).
template <int N>
inline void covariance(const float* u, const float* d, float* p) {
  auto U = [&](int i, int j) -> float { return i == j ? 1.0f : (i < j ? u[off_index<N>(i, j)] : 0.0f); };
  for (int i = 0; i < N; ++i)
    for (int j = i; j < N; ++j) {
      float s = 0.0f;
      for (int k = j; k < N; ++k) s += U(i, k) * d[k] * U(j, k);
      p[packed_index<N>(i, j)] = s;
    }
}

// Bierman's UD measurement update with measurement variance `r`: on return U D U^T holds
// P - P x x^T P / (r + x^T P x), `gain` holds P x / (r + x^T P x) (computed from the old P), and the
// return value is r + x^T P x. With r = lambda this is eq. 6-7 before the division by lambda.
template <int N, typename T>
[[gnu::always_inline]] inline T bierman_update(T* u, T* d, const T x[N], float r, T gain[N]) {
  T f[N], v[N];
  for (int j = 0; j < N; ++j) {
    T s = x[j];
    for (int i = 0; i < j; ++i) s += u[off_index<N>(i, j)] * x[i];
    f[j] = s;
    v[j] = d[j] * s;
  }
  // The running sums alpha_j = r + sum_{k<=j} f_k v_k come first so that their N reciprocals are
  // independent divisions (pipelined) instead of a chain of 2N dependent ones.
  T alpha[N], inv[N];
  alpha[0] = r + v[0] * f[0];
  for (int j = 1; j < N; ++j) alpha[j] = alpha[j - 1] + v[j] * f[j];
  for (int j = 0; j < N; ++j) inv[j] = 1.0f / alpha[j];
  d[0] *= r * inv[0];
  gain[0] = v[0];
  for (int j = 1; j < N; ++j) {
    const T p = -f[j] * inv[j - 1];
    d[j] *= alpha[j - 1] * inv[j];
    for (int i = 0; i < j; ++i) {
      T& uij = u[off_index<N>(i, j)];
      const T old = uij;
      uij = old + gain[i] * p;
      gain[i] += old * v[j];
    }
    gain[j] = v[j];
  }
  for (int j = 0; j < N; ++j) gain[j] *= inv[N - 1];
  return alpha[N - 1];
}

// Smallest value a D entry keeps: below it, float32 arithmetic turns denormal (slow) and the direction's
// gain would be zero anyway.
inline constexpr float kMinD = 1e-20f;

// One RLS step (eq. 5-7) for sample y (C values) with predictor x, forgetting factor lambda, and the
// bounds of the header comment (D entries <= d_max, trace(P) <= trace_max). Returns trace(P) after the step.
template <int N, int C>
[[gnu::always_inline]] inline float update(Model<N, C>& m, const float x[N], const float y[C], float lambda,
                                           float d_max, float trace_max) {
  float e[C];
  for (int c = 0; c < C; ++c) e[c] = y[c] - predict(m, c, x);  // eq. 5, a-priori error
  float gain[N];
  bierman_update<N>(m.u, m.d, x, lambda, gain);
  for (int c = 0; c < C; ++c)
    for (int k = 0; k < N; ++k) m.beta[c][k] += gain[k] * e[c];  // eq. 6
  const float inv_lambda = 1.0f / lambda;                          // eq. 7
  for (int k = 0; k < N; ++k) m.d[k] = fast_min(fast_max(m.d[k] * inv_lambda, kMinD), d_max);
  float t = trace<N>(m.u, m.d);
  if (t > trace_max) {
    const float scale = trace_max / t;
    for (int k = 0; k < N; ++k) m.d[k] = fast_max(m.d[k] * scale, kMinD);
    t = trace<N>(m.u, m.d);
  }
  return t;
}

}  // namespace temporal::phlm::rls
