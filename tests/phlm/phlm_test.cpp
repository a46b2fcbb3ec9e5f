// PHLM (seed 003) on synthetic sequences: the numerically hard cases of issue 5, each with a numeric assertion.
#include "temporal/io/exr.h"
#include "temporal/phlm/phlm.h"

#include "filter_frames.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <functional>
#include <random>
#include <utility>

namespace {

using namespace temporal;
using namespace temporal::phlm;
using namespace temporal::phlm::test_frames;

bool all_finite(const Image& img) {
  for (const auto& n : img.channel_names())
    if (img.channel_type(n) == ChannelType::Float && count_non_finite({img.plane(n), img.pixel_count()}) != 0)
      return false;
  return true;
}

// Bound of trace(P) enforced by the filter with the default parameters: trace_factor * N * p_init.
constexpr double kTraceBound = 4.0 * 4.0 * 1000.0;

float truth(int x, int y, int c) { return 0.2f + 0.05f * float(x) + 0.03f * float(y) + 0.05f * float(c); }

TEST(Phlm, StateSizeFollowsTheData) {
  EXPECT_EQ(phlm_state_floats(3), 26);  // beta 12 + P 10 + z 3 + s 1
  EXPECT_EQ(phlm_state_floats(1), 7);   // beta 2 + P 3 + z 1 + s 1
  EXPECT_EQ(PhlmFilter::state_channel_names(3).size(), 26u);
  EXPECT_EQ(PhlmFilter::state_channel_names(1).size(), 7u);
}

// Section 5.1's feature weight with hand-computed values: grey frames (YCgCo Y = the value), frame 0 all 0.5,
// frame 1 with 0.3 at (1,1) and 0.9 at (3,3). At pixel (2,2): Delta(Y) = 0.9 - 0.3 = 0.6, the previous feature
// is 0.5, l = min(|0.5 - 0.3|, |0.5 - 0.9|) = 0.2, the binomial low-pass is (8 - 1 + 1.2) / 16 = 0.5125.
// The frames of the feature tests below, through a fresh filter with `params`: frame 0 uniform 0.5, frame 1 with
// 0.3 at (1,1) and 0.9 at (3,3), motion (vx, vy) at every pixel; returns frame 1's output (debug layers on).
Image feature_frames(const PhlmParams& params, int w, int h, float vx, float vy) {
  Image m(w, h);
  float* mx = m.add_channel("motion.X", vx);
  float* my = m.add_channel("motion.Y", vy);
  const Image f0 = make_frame(w, h, [](int, int, int) { return 0.5f; });
  const Image f1 = make_frame(w, h, [](int x, int y, int) {
    return (x == 1 && y == 1) ? 0.3f : ((x == 3 && y == 3) ? 0.9f : 0.5f);
  });
  PhlmFilter filter(params);
  Image out;
  FilterInput in = input_for(f0, true);
  in.motion_x = mx;
  in.motion_y = my;
  in.debug = true;
  EXPECT_TRUE(filter.process(in, out));
  in.color = &f1;
  in.reset = false;
  EXPECT_TRUE(filter.process(in, out));
  return out;
}

TEST(Phlm, FeatureWeightFollowsSection51) {
  for (const float v : {0.0f, 1.0f}) {  // |motion| in pixels
    const Image out = feature_frames(PhlmParams{}, 5, 5, v, 0.0f);
    // alpha = (a l^2 + b v l^3) / (l + Delta), a = 0.125, b = 0.25.
    const double alpha = (0.125 * 0.04 + 0.25 * v * 0.008) / 0.8;
    EXPECT_NEAR(out.plane("debug.alpha")[12], alpha, 1e-6) << "v = " << v;
    EXPECT_NEAR(out.plane("debug.featureG")[12], 0.5 + alpha * (0.5125 - 0.5), 1e-6);
    // The literal eq. 1 reading (ablation --feature-alpha eq1): alpha weighs the history.
    PhlmParams eq1;
    eq1.alpha_reading = "eq1";
    const Image literal = feature_frames(eq1, 5, 5, v, 0.0f);
    EXPECT_NEAR(literal.plane("debug.featureG")[12], alpha * 0.5 + (1.0 - alpha) * 0.5125, 1e-6);
  }
}

// Issue 24: the linear form of phi (--feature-phi linear, UE4's HistoryFactor = DistToClamp * HistoryAmount) on the
// frames of FeatureWeightFollowsSection51: phi = (a + b v) l, so at pixel (2,2) (l = 0.2, Delta = 0.6)
//   v = 0: alpha = 0.125 * 0.2 / 0.8 = 0.03125             (the printed form: 0.00625, 5x smaller)
//   v = 1: alpha = (0.125 + 0.25) * 0.2 / 0.8 = 0.09375    (the printed form: 0.00875)
//   v = 5: alpha = (0.125 + 1.25) * 0.2 / 0.8 = 0.34375
// and the feature moves by alpha of the way to the low-pass: z = 0.5 + alpha (0.5125 - 0.5). With l = 0 (the
// feature on the box's edge) both forms give alpha = 0; with a flat box (Delta = 0, l = 0) alpha = 0 (0/0 rule).
TEST(Phlm, LinearFeatureWeightFollowsUe4HistoryFactor) {
  for (const auto& [v, expected] : {std::pair{0.0f, 0.03125}, std::pair{1.0f, 0.09375}, std::pair{5.0f, 0.34375}}) {
    // 5 x 9 pixels, the motion v pixels per frame along y: q = p + motion = (2, 2 + v) stays on screen, and frame 0
    // is uniform, so the fetched feature is 0.5 wherever it comes from.
    PhlmParams linear;
    linear.feature_phi = "linear";
    const Image out = feature_frames(linear, 5, 9, 0.0f, v);
    EXPECT_NEAR(out.plane("debug.alpha")[12], expected, 1e-6) << "v = " << v;
    EXPECT_NEAR(out.plane("debug.featureG")[12], 0.5 + expected * (0.5125 - 0.5), 1e-6) << "v = " << v;
    // Pixel (4, 0), whose whole neighbourhood is 0.5 (flat box, Delta = 0, l = 0; q = (4, v) on screen): nothing
    // to blend.
    EXPECT_EQ(out.plane("debug.alpha")[4], 0.0f) << "v = " << v;
    EXPECT_EQ(out.plane("debug.reset")[4], 0.0f) << "v = " << v;
  }
  PhlmParams bad;
  bad.feature_phi = "cubic";
  PhlmFilter rejected(bad);
  const Image f0 = make_frame(4, 4, [](int, int, int) { return 0.5f; });
  Image out;
  const Status s = rejected.process(input_for(f0, true), out);
  ASSERT_FALSE(s);
  EXPECT_NE(s.error().message.find("--feature-phi 'cubic'"), std::string::npos);
}

// Issue 16: with the feature off (--no-feature, x = [1]) PHLM is an intercept-only RLS, i.e. per pixel the
// lambda-weighted running mean of its samples with the prior of the reset. From eq. 6-7 with x = 1: the
// information I = 1 / P and S = I beta follow I <- lambda I + 1, S <- lambda S + y, starting at the reset (frame 0)
// from I = 1 / p_init, S = y0 / p_init; the output after frame n is S_n / I_n:
//   f_n = (lambda^(n+1) y0 / p_init + sum_k lambda^(n-k) y_k) / (lambda^(n+1) / p_init + sum_k lambda^(n-k)).
// The sequence is static (no motion) and built so the box test never fires: grey values, and in every 3x3
// neighbourhood anchor pixels at 0 and 1 (columns x = 0 mod 3, 0 on even rows, 1 on odd rows), so every box is
// [0, 1] in Y and [0, 0] in Cg, Co; the other pixels take a new random grey in [0.05, 0.95] every frame.
TEST(Phlm, InterceptOnlyIsAPerPixelRunningMean) {
  const int w = 8, h = 5, frames = 60;
  for (const float lambda : {1.0f, 0.998f, 0.9f}) {
    std::mt19937 rng(41);
    std::uniform_real_distribution<float> u(0.05f, 0.95f);
    PhlmParams p;
    p.lambda = lambda;
    p.no_feature = true;
    PhlmFilter filter(p);
    PhlmParams with_feature = p;
    with_feature.no_feature = false;
    PhlmFilter full(with_feature);
    std::vector<double> S(std::size_t(w * h)), I(std::size_t(w * h));
    Image out, out_full;
    double largest_feature_effect = 0.0;
    for (int t = 0; t < frames; ++t) {
      Image frame(w, h);
      float* r = frame.add_channel("R");
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) r[y * w + x] = x % 3 == 0 ? float(y % 2) : u(rng);
      std::copy(r, r + w * h, frame.add_channel("G"));
      std::copy(r, r + w * h, frame.add_channel("B"));
      FilterInput in = input_for(frame, t == 0);
      in.debug = true;
      FilterStats stats;
      ASSERT_TRUE(filter.process(in, out, &stats));
      EXPECT_EQ(stats.clamped, 0u) << "frame " << t;  // the box test never fired
      EXPECT_EQ(stats.history_resets, t == 0 ? std::size_t(w * h) : 0u);
      ASSERT_TRUE(full.process(in, out_full));
      for (std::size_t i = 0; i < std::size_t(w * h); ++i) {
        if (t == 0) {
          I[i] = 1.0 / 1000.0;  // p_init
          S[i] = double(r[i]) / 1000.0;
        }
        I[i] = lambda * I[i] + 1.0;
        S[i] = lambda * S[i] + double(r[i]);
        for (const auto& c : kRgb) ASSERT_NEAR(out.plane(c)[i], S[i] / I[i], 2e-6) << "frame " << t << " pixel " << i;
        largest_feature_effect = std::max(largest_feature_effect, std::fabs(double(out_full.plane("G")[i]) - S[i] / I[i]));
      }
    }
    // The slopes never moved, and the feature does change the full method's output on this sequence (so the
    // comparison above is not vacuous).
    for (std::size_t i = 0; i < std::size_t(w * h); ++i) EXPECT_EQ(filter.state().plane("beta.G1")[i], 0.0f);
    EXPECT_GT(largest_feature_effect, 1e-3) << "lambda " << lambda;
  }
}

TEST(Phlm, TwentyThousandFramesOfAStaticNoisyImageStayStable) {
  const int w = 8, h = 8;
  std::mt19937 rng(1234);
  std::normal_distribution<float> noise(0.0f, 0.1f);
  PhlmFilter filter;
  Image out;
  double sq_in = 0.0, sq_out = 0.0;
  std::size_t samples = 0;
  double max_trace = 0.0;
  for (int t = 0; t < 20000; ++t) {
    Image frame = make_frame(w, h, [&](int x, int y, int c) { return truth(x, y, c) + noise(rng); });
    FilterStats stats;
    ASSERT_TRUE(filter.process(input_for(frame, t == 0), out, &stats));
    max_trace = std::max(max_trace, stats.max_trace_p);
    ASSERT_TRUE(all_finite(out)) << "frame " << t;
    if (t >= 19000) {
      // Interior pixels: at the border the clamped 3x3 neighbourhood repeats samples, its box is narrower
      // and the box test resets models more often.
      for (int c = 0; c < 3; ++c)
        for (int y = 1; y < h - 1; ++y)
          for (int x = 1; x < w - 1; ++x) {
            const std::size_t i = std::size_t(y * w + x);
            const double e_out = out.plane(kRgb[std::size_t(c)])[i] - truth(x, y, c);
            const double e_in = frame.plane(kRgb[std::size_t(c)])[i] - truth(x, y, c);
            sq_out += e_out * e_out;
            sq_in += e_in * e_in;
            ++samples;
          }
    }
  }
  const double rmse_in = std::sqrt(sq_in / double(samples)), rmse_out = std::sqrt(sq_out / double(samples));
  EXPECT_NEAR(rmse_in, 0.1, 0.01);
  // The filter must reduce the noise substantially after 20,000 frames (and not drift): measured 0.028.
  EXPECT_LT(rmse_out, 0.4 * rmse_in) << "input RMSE " << rmse_in << " output RMSE " << rmse_out;
  EXPECT_LE(max_trace, kTraceBound);
  EXPECT_TRUE(all_finite(filter.state()));
}

TEST(Phlm, ConstantColourIsReproduced) {
  PhlmFilter filter;
  Image out;
  const Image frame = make_frame(6, 5, [](int, int, int c) { return 0.25f + 0.25f * float(c); });
  for (int t = 0; t < 300; ++t) {
    FilterStats stats;
    ASSERT_TRUE(filter.process(input_for(frame), out, &stats));
    EXPECT_LE(stats.max_trace_p, kTraceBound);
  }
  for (int c = 0; c < 3; ++c)
    for (std::size_t i = 0; i < out.pixel_count(); ++i)
      EXPECT_NEAR(out.plane(kRgb[std::size_t(c)])[i], 0.25f + 0.25f * float(c), 1e-5f);
}

TEST(Phlm, BlackStaysBlack) {
  PhlmFilter filter;
  Image out;
  const Image frame = make_frame(4, 4, [](int, int, int) { return 0.0f; });
  for (int t = 0; t < 1000; ++t) ASSERT_TRUE(filter.process(input_for(frame), out));
  EXPECT_TRUE(all_finite(out));
  EXPECT_TRUE(all_finite(filter.state()));
  for (const auto& c : kRgb)
    for (std::size_t i = 0; i < out.pixel_count(); ++i) EXPECT_EQ(out.plane(c)[i], 0.0f);
}

TEST(Phlm, HdrValuesAround1e4) {
  std::mt19937 rng(99);
  std::normal_distribution<float> noise(0.0f, 1000.0f);
  PhlmFilter filter;
  Image out;
  double sq_in = 0.0, sq_out = 0.0, max_trace = 0.0;
  for (int t = 0; t < 2000; ++t) {
    Image frame = make_frame(8, 8, [&](int x, int, int) { return 1e4f + 500.0f * float(x) + noise(rng); });
    FilterStats stats;
    ASSERT_TRUE(filter.process(input_for(frame), out, &stats));
    max_trace = std::max(max_trace, stats.max_trace_p);
    ASSERT_TRUE(all_finite(out));
    if (t >= 1500)
      for (int y = 1; y < 7; ++y)
        for (int x = 1; x < 7; ++x) {
          const std::size_t i = std::size_t(y * 8 + x);
          const double ref = 1e4 + 500.0 * x;
          sq_out += std::pow(out.plane("G")[i] - ref, 2.0);
          sq_in += std::pow(frame.plane("G")[i] - ref, 2.0);
        }
  }
  EXPECT_LT(std::sqrt(sq_out), 0.5 * std::sqrt(sq_in));
  EXPECT_LE(max_trace, kTraceBound);
}

TEST(Phlm, SuddenStepIsFollowedAtOnce) {
  PhlmFilter filter;
  Image out;
  const Image dark = make_frame(6, 6, [](int, int, int) { return 0.2f; });
  const Image bright = make_frame(6, 6, [](int, int, int) { return 0.8f; });
  for (int t = 0; t < 100; ++t) ASSERT_TRUE(filter.process(input_for(dark), out));
  FilterStats stats;
  ASSERT_TRUE(filter.process(input_for(bright), out, &stats));
  // The old models predict 0.2, outside the new 3x3 box [0.8, 0.8]: Algorithm 1 lines 16-18 clip and reset.
  EXPECT_EQ(stats.clamped, 36u);
  for (const auto& c : kRgb)
    for (std::size_t i = 0; i < out.pixel_count(); ++i) EXPECT_NEAR(out.plane(c)[i], 0.8f, 1e-5f);
}

TEST(Phlm, PixelAlternatingEveryFrame) {
  PhlmFilter filter;
  Image out;
  double max_trace = 0.0;
  for (int t = 0; t < 3000; ++t) {
    const float v = (t % 2) ? 1.0f : 0.0f;
    Image frame = make_frame(5, 5, [&](int x, int y, int) { return (x == 2 && y == 2) ? v : 0.5f; });
    FilterStats stats;
    ASSERT_TRUE(filter.process(input_for(frame), out, &stats));
    max_trace = std::max(max_trace, stats.max_trace_p);
    ASSERT_TRUE(all_finite(out));
    // The output stays inside the range of the inputs (the box test clips anything outside).
    for (const auto& c : kRgb)
      for (std::size_t i = 0; i < out.pixel_count(); ++i) {
        ASSERT_GE(out.plane(c)[i], -1e-4f);
        ASSERT_LE(out.plane(c)[i], 1.0f + 1e-4f);
      }
  }
  EXPECT_LE(max_trace, kTraceBound);
  EXPECT_TRUE(all_finite(filter.state()));
}

TEST(Phlm, NanAndInfNeverEnterAModel) {
  PhlmFilter filter;
  Image out;
  std::mt19937 rng(5);
  std::normal_distribution<float> noise(0.0f, 0.05f);
  auto noisy = [&] { return make_frame(6, 6, [&](int x, int y, int c) { return truth(x, y, c) + noise(rng); }); };
  for (int t = 0; t < 20; ++t) ASSERT_TRUE(filter.process(input_for(noisy()), out));
  const Image before = filter.state();
  Image bad = noisy();
  bad.plane("R")[7] = NAN;
  bad.plane("G")[20] = INFINITY;
  bad.plane("B")[35] = -INFINITY;
  FilterStats stats;
  ASSERT_TRUE(filter.process(input_for(bad), out, &stats));
  EXPECT_EQ(stats.non_finite, 3u);
  EXPECT_TRUE(all_finite(out));
  EXPECT_TRUE(all_finite(filter.state()));
  // The models of the three pixels are carried over unchanged (beta and P bit for bit).
  for (const auto& name : PhlmFilter::state_channel_names(3)) {
    if (name.rfind("beta.", 0) != 0 && name.rfind("P.", 0) != 0) continue;
    for (std::size_t i : {std::size_t(7), std::size_t(20), std::size_t(35)})
      EXPECT_EQ(filter.state().plane(name)[i], before.plane(name)[i]) << name << " at " << i;
  }
  // A frame that is entirely NaN keeps every model and outputs the previous predictions.
  Image all_nan = make_frame(6, 6, [](int, int, int) { return NAN; });
  ASSERT_TRUE(filter.process(input_for(all_nan), out, &stats));
  EXPECT_EQ(stats.non_finite, 36u);
  EXPECT_TRUE(all_finite(out));
  EXPECT_TRUE(all_finite(filter.state()));
}

TEST(Phlm, CameraCutResetsTheHistory) {
  std::mt19937 rng(17);
  std::normal_distribution<float> noise(0.0f, 0.1f);
  auto noisy = [&] { return make_frame(6, 6, [&](int x, int y, int c) { return truth(x, y, c) + noise(rng); }); };
  PhlmFilter filter;
  Image out;
  for (int t = 0; t < 50; ++t) ASSERT_TRUE(filter.process(input_for(noisy()), out));
  const Image frame = noisy();
  // Without a cut the output is filtered (differs from the input) ...
  PhlmFilter copy = filter;
  Image out_nocut;
  ASSERT_TRUE(copy.process(input_for(frame, false), out_nocut));
  double diff = 0.0;
  for (const auto& c : kRgb)
    for (std::size_t i = 0; i < out.pixel_count(); ++i) diff += std::fabs(out_nocut.plane(c)[i] - frame.plane(c)[i]);
  EXPECT_GT(diff / 108.0, 0.01);
  // ... with a cut every model restarts from the input (section 6), so the output is the input.
  FilterStats stats;
  ASSERT_TRUE(filter.process(input_for(frame, true), out, &stats));
  EXPECT_EQ(stats.history_resets, 36u);
  for (const auto& c : kRgb)
    for (std::size_t i = 0; i < out.pixel_count(); ++i) EXPECT_NEAR(out.plane(c)[i], frame.plane(c)[i], 1e-5f);
  for (std::size_t i = 0; i < out.pixel_count(); ++i) EXPECT_EQ(filter.state().plane("beta.R1")[i], 0.0f);
}

TEST(Phlm, ModelsFollowTheMotionAndResetOffScreen) {
  // A texture moving right by one pixel per frame: the surface at p was at p - 1, so motion.X = -1.
  const int w = 10, h = 4;
  auto tex = [](int u) { return 0.3f + 0.4f * float((u * 7) % 5) / 4.0f; };
  Image motion(w, h);
  float* mx = motion.add_channel("motion.X", -1.0f);
  float* my = motion.add_channel("motion.Y", 0.0f);
  for (const char* fetch : {"bilinear", "nearest", "catmull-rom"}) {  // integer motion: every fetch is exact
  PhlmParams params;
  params.model_fetch = fetch;
  PhlmFilter filter(params);
  Image out;
  for (int t = 0; t < 30; ++t) {
    Image frame = make_frame(w, h, [&](int x, int, int) { return tex(x - t + 100); });
    FilterInput in = input_for(frame);
    in.motion_x = mx;
    in.motion_y = my;
    FilterStats stats;
    ASSERT_TRUE(filter.process(in, out, &stats));
    if (t > 0) {
      EXPECT_EQ(stats.history_resets, std::size_t(h));  // the left column came from off-screen
    }
    for (const auto& c : kRgb)
      for (std::size_t i = 0; i < out.pixel_count(); ++i)
        ASSERT_NEAR(out.plane(c)[i], frame.plane(c)[i], 1e-4f) << fetch;
  }
  }
}

TEST(Phlm, OneChannelPayloadUsesTwoPredictors) {
  Image frame(5, 5);
  float* ao = frame.add_channel("ssao.Y", 0.6f);
  ao[12] = 0.2f;
  PhlmFilter filter;
  Image out;
  FilterInput in;
  in.color = &frame;
  in.channels = {"ssao.Y"};
  for (int t = 0; t < 100; ++t) ASSERT_TRUE(filter.process(in, out));
  EXPECT_TRUE(out.plane("ssao.Y"));
  EXPECT_EQ(filter.state().channel_count(), 7u);
  EXPECT_TRUE(filter.state().plane("beta.Y1"));
  EXPECT_TRUE(filter.state().plane("P.U01"));
  EXPECT_NEAR(out.plane("ssao.Y")[12], 0.2f, 1e-5f);
  EXPECT_NEAR(out.plane("ssao.Y")[0], 0.6f, 1e-5f);
}

TEST(Phlm, ResumedRunEqualsUninterruptedRunBitForBit) {
  const int w = 9, h = 7, frames = 24, split = 11;
  std::vector<Image> seq;
  std::mt19937 rng(3);
  std::normal_distribution<float> noise(0.0f, 0.1f);
  Image motion(w, h);
  float* mx = motion.add_channel("motion.X", 0.0f);
  float* my = motion.add_channel("motion.Y", 0.0f);
  for (std::size_t i = 0; i < motion.pixel_count(); ++i) {
    mx[i] = -0.37f + 0.01f * float(i % 5);
    my[i] = 0.21f;
  }
  for (int t = 0; t < frames; ++t)
    seq.push_back(make_frame(w, h, [&](int x, int y, int c) { return truth(x, y, c) + noise(rng); }));
  auto step = [&](PhlmFilter& f, int t, Image& out) {
    FilterInput in = input_for(seq[std::size_t(t)], t == 0);
    in.motion_x = mx;
    in.motion_y = my;
    ASSERT_TRUE(f.process(in, out));
  };
  PhlmFilter whole;
  Image out_whole;
  for (int t = 0; t < frames; ++t) step(whole, t, out_whole);

  PhlmFilter first;
  Image out;
  for (int t = 0; t < split; ++t) step(first, t, out);
  const auto dir = test::scratch_dir("phlm-resume");
  const std::string path = (dir / "state.exr").string();
  ASSERT_TRUE(write_exr(path, first.state_with_covariance()));
  auto loaded = read_exr(path);
  ASSERT_TRUE(loaded);
  EXPECT_TRUE(loaded->plane("Pmat.P00"));  // the symmetric P is written for inspection
  PhlmFilter resumed;
  const Status resumed_ok = resumed.set_state(*loaded, 3);
  ASSERT_TRUE(resumed_ok) << resumed_ok.error().message;
  Image out_resumed;
  for (int t = split; t < frames; ++t) step(resumed, t, out_resumed);
  for (const auto& c : kRgb)
    EXPECT_EQ(std::memcmp(out_resumed.plane(c), out_whole.plane(c), out_whole.pixel_count() * sizeof(float)), 0) << c;
}

TEST(Phlm, RejectsAStateWithMissingPlanes) {
  Image bad(4, 4);
  bad.add_channel("beta.R0");
  PhlmFilter filter;
  const Status s = filter.set_state(bad, 3);
  ASSERT_FALSE(s);
  EXPECT_NE(s.error().message.find("beta.R1"), std::string::npos);
}

}  // namespace
