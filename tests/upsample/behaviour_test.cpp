// Behaviour of the methods on generated sequences (synthetic.h): convergence, disocclusion, depth edges,
// camera motion, NaN input, camera cuts, input errors. Tolerances are stated next to each assertion.
#include "synthetic.h"

#include "temporal/core/jitter.h"
#include "temporal/upsample/methods.h"
#include "temporal/upsample/upsample.h"

#include <gtest/gtest.h>
#include <test_support.h>

#include <cmath>
#include <cstring>
#include <cstdio>
#include <functional>
#include <limits>
#include <tuple>

namespace up = temporal::upsample;
using temporal::Image;
using temporal::test::make_frame;
using temporal::test::SyntheticFrame;
using temporal::test::SyntheticScene;

namespace {

const std::vector<std::string> kRGB = {"R", "G", "B"};

// Options of a method with command-line style arguments (the way a user sets them).
up::Options options_for(const std::string& method, const std::vector<std::string>& args = {}) {
  auto o = up::make_options(method, args);
  EXPECT_TRUE(o.has_value()) << (o ? "" : o.error().message);
  return o ? *o : up::Options{};
}

struct SeqRun {
  Image output;           // last frame's output (copy)
  SyntheticFrame frame;   // last frame's inputs and reference
  up::FrameStats stats;   // last frame's stats
  std::size_t total_non_finite = 0;
};

// Runs frames 0..count-1; `edit` may change a frame's inputs before it is processed.
SeqRun run_seq(const SyntheticScene& scene, up::Options o, int count,
        const std::function<void(int, SyntheticFrame&, bool&)>& edit = {}) {
  up::Upsampler u(o);
  SeqRun r;
  for (int t = 0; t < count; ++t) {
    SyntheticFrame f = make_frame(scene, t);
    bool cut = false;
    if (edit) edit(t, f, cut);
    auto out = u.process(f.gbuffer, f.low, kRGB, cut, &r.stats);
    EXPECT_TRUE(out.has_value()) << (out ? "" : out.error().message);
    if (!out) return r;
    r.total_non_finite += r.stats.non_finite_input;
    if (t == count - 1) {
      r.output = **out;
      r.frame = std::move(f);
    }
  }
  return r;
}

// Mean absolute error over R,G,B where pred(i) holds; also the largest error.
struct Err {
  double mean = 0, max = 0;
  std::size_t n = 0;
};
Err error(const Image& out, const Image& ref, const std::function<bool(std::size_t)>& pred = {}) {
  Err e;
  double sum = 0;
  for (const auto& c : kRGB) {
    const float* a = out.plane(c);
    const float* b = ref.plane(c);
    for (std::size_t i = 0; i < out.pixel_count(); ++i) {
      if (pred && !pred(i)) continue;
      const double d = std::abs(double(a[i]) - double(b[i]));
      sum += d;
      e.max = std::max(e.max, d);
      ++e.n;
    }
  }
  e.mean = e.n ? sum / double(e.n) : 0.0;
  return e;
}

bool all_finite(const Image& img) {
  for (const auto& c : img.channel_names())
    if (const float* p = img.plane(c))
      for (std::size_t i = 0; i < img.pixel_count(); ++i)
        if (!std::isfinite(p[i])) return false;
  return true;
}

}  // namespace

TEST(Upsample, TemporalStaticSceneIsExactAfterKSquaredFrames) {
  SyntheticScene scene;  // static camera, no object
  const SeqRun r = run_seq(scene, options_for("temporal"), scene.k * scene.k);
  // Every full-resolution pixel has been shaded once and carried unchanged (motion 0): float copies.
  const Err e = error(r.output, r.frame.reference);
  EXPECT_LE(e.max, 1e-6) << "mean " << e.mean;
  EXPECT_EQ(r.stats.hole_pixels, 0u);
}

TEST(Upsample, HerzogStaticSceneConverges) {
  // Pixels at least k from the border: at the border only one side's samples exist, which biases every
  // kernel-based estimate (spatial included).
  auto interior = [](const SyntheticScene& sc) {
    return [=](std::size_t i) {
      const int X = int(i % sc.width), Y = int(i / sc.width);
      return X >= sc.k && Y >= sc.k && X < sc.width - sc.k && Y < sc.height - sc.k;
    };
  };
  // A payload with detail at the scale of the low-resolution grid (period 20 px for k = 4).
  SyntheticScene scene;
  scene.period = 20.0f;
  const int kk = scene.k * scene.k;
  const SeqRun spatial = run_seq(scene, options_for("spatial"), kk);
  const Err es = error(spatial.output, spatial.frame.reference, interior(scene));
  const SeqRun r = run_seq(scene, options_for("herzog"), kk);
  const Err e = error(r.output, r.frame.reference, interior(scene));
  std::printf("herzog static (period 20), after k*k frames: mean %.5f max %.5f; spatial mean %.5f max %.5f\n",
              e.mean, e.max, es.mean, es.max);
  // The published image kernel (fall-off gamma * w_f at most 4 over the low-res diagonal, times the spatial hat)
  // keeps ~1/4 of the weight on the pixel's own sample at convergence, so a slight blur remains: below 0.06 here
  // (payload amplitude 0.3), and below the spatial method's error.
  EXPECT_LE(e.max, 0.06);
  EXPECT_LT(e.mean, 0.85 * es.mean);
  // The fused variant (eq. 7 with the previous frame's w_f) converges alike in a static scene.
  const SeqRun rl = run_seq(scene, options_for("herzog", {"--lagged-wf"}), kk);
  const Err el = error(rl.output, rl.frame.reference, interior(scene));
  EXPECT_LE(el.max, 0.06);
  EXPECT_LT(el.mean, 0.85 * es.mean);
  // With a steeper kernel (cap of gamma * w_f raised to 64) the result approaches the exact payload.
  SyntheticScene smooth;
  const up::Options sharp = options_for("herzog", {"--kernel-gamma", "64", "--max-kernel-gamma", "64"});
  const SeqRun rs = run_seq(smooth, sharp, 2 * kk);
  const Err e2 = error(rs.output, rs.frame.reference, interior(smooth));
  std::printf("herzog static (period 40), gamma cap 64, after 2 k*k frames: mean %.5f max %.5f\n", e2.mean, e2.max);
  EXPECT_LE(e2.mean, 0.001);
  EXPECT_LE(e2.max, 0.02);
}

TEST(Upsample, HerzogFallbackIsSpatialUpsampling) {
  // Seed 000 sections 3.3 and 3.5: where gamma w_f = 0 the method "falls back to spatial upsampling". With a = 0
  // (eq. 8: w_f = 0 everywhere) the image kernel is the spatial baseline's hat and eq. 7 gives the history no
  // weight, so every frame must equal `spatial`'s; with the default a, the first frame (no history, w_f = 0) must.
  // Tolerance 1e-6: the two compute the same weights with products in another order.
  SyntheticScene scene;
  scene.object = true;
  scene.object_velocity = {2.0f, 1.0f};
  scene.camera_velocity = {0.5f, -0.25f};
  up::Upsampler spatial(options_for("spatial")), herzog_a0(options_for("herzog", {"--a", "0"}));
  up::Upsampler herzog(options_for("herzog")), literal(options_for("herzog", {"--fallback", "flat", "--a", "0"}));
  auto max_diff = [](const Image& a, const Image& b) {
    double d = 0;
    for (const auto& c : kRGB)
      for (std::size_t i = 0; i < a.pixel_count(); ++i)
        d = std::max(d, std::abs(double(a.plane(c)[i]) - double(b.plane(c)[i])));
    return d;
  };
  for (int t = 0; t < 8; ++t) {
    SyntheticFrame f = make_frame(scene, t);
    auto s = spatial.process(f.gbuffer, f.low, kRGB, false);
    auto h0 = herzog_a0.process(f.gbuffer, f.low, kRGB, false);
    auto h = herzog.process(f.gbuffer, f.low, kRGB, false);
    auto fl = literal.process(f.gbuffer, f.low, kRGB, false);
    ASSERT_TRUE(s && h0 && h && fl);
    EXPECT_LE(max_diff(**s, **h0), 1e-6) << "frame " << t;
    if (t == 0) {
      EXPECT_LE(max_diff(**s, **h), 1e-6);
    }
    // The literal reading (eq. 3 alone, a box at gamma = 0) is not the spatial baseline.
    EXPECT_GT(max_diff(**s, **fl), 1e-3) << "frame " << t;
    if (t == 0) {
      // By hand at pixel (1, 1) of frame 0 (sub-pixel (0, 0)): its taps are samples (0, 0), (1, 0), (0, 1), (1, 1)
      // of the background plane (equal depth and normal: equal geometric weights), 1/4 of the low-resolution
      // spacing from the first. Hat: (3/4 3/4, 1/4 3/4, 3/4 1/4, 1/4 1/4); box: 1/4 each.
      const int lw = f.low.width();
      for (const auto& c : kRGB) {
        const float* l = f.low.plane(c);
        const double v00 = l[0], v10 = l[1], v01 = l[lw], v11 = l[lw + 1];
        const std::size_t p = std::size_t(scene.width) + 1;
        EXPECT_NEAR((*h)->plane(c)[p], (9 * v00 + 3 * v10 + 3 * v01 + v11) / 16, 1e-6) << c;
        EXPECT_NEAR((*fl)->plane(c)[p], (v00 + v10 + v01 + v11) / 4, 1e-6) << c;
      }
    }
  }
}

TEST(Upsample, HerzogAblationFixedWfZeroIsSpatial) {
  // `--fixed-wf 0`: w_f = 0 everywhere, so the kernel is spatial's (gamma w_f = 0, the fallback) and eq. 7 gives
  // the history no weight: every frame equals `spatial` (the same check as a = 0 above, through the ablation).
  SyntheticScene scene;
  scene.object = true;
  scene.object_velocity = {2.0f, 1.0f};
  up::Upsampler spatial(options_for("spatial")), fixed0(options_for("herzog", {"--fixed-wf", "0"}));
  for (int t = 0; t < 6; ++t) {
    SyntheticFrame f = make_frame(scene, t);
    auto s = spatial.process(f.gbuffer, f.low, kRGB, false);
    auto h = fixed0.process(f.gbuffer, f.low, kRGB, false);
    ASSERT_TRUE(s && h);
    for (const auto& c : kRGB)
      for (std::size_t i = 0; i < (*s)->pixel_count(); ++i)
        ASSERT_NEAR((*s)->plane(c)[i], (*h)->plane(c)[i], 1e-6) << c << " " << i << " frame " << t;
  }
  EXPECT_FALSE(up::make_options("herzog", {"--fixed-wf", "-0.5"}).has_value());
  EXPECT_FALSE(up::make_options("herzog", {"--gradient-filter", "box"}).has_value());
}

TEST(Upsample, HerzogAblationGradientFilter) {
  // A uniform, static payload converges exactly (any weighted mean of one value is that value), so the three
  // previous relative gradients are 0. Halving the payload at frame T gives g_t = (h~ - h_r) / max(|h~|, |h_r|)
  // = (L/2 - L) / L = -0.5 everywhere; the uniform field passes the spatial low-pass unchanged. Section 3.5.1's
  // filter gives |0.4 x -0.5| = 0.2, the ablation (`--gradient-filter none`) |g_t| = 0.5, and w_f (eq. 8,
  // a = 1) (1 - 0.2)^2 = 0.64 and 0.25.
  SyntheticScene scene;
  scene.amplitude = 0.0f;
  const int T = 2 * scene.k * scene.k;
  auto halve = [&](int t, SyntheticFrame& f, bool&) {
    if (t != T) return;
    for (const auto& c : kRGB)
      for (std::size_t i = 0; i < f.low.pixel_count(); ++i) f.low.plane(c)[i] *= 0.5f;
  };
  for (const auto& [filter, gradient, wf] :
       {std::tuple<std::string, float, float>{"temporal", 0.2f, 0.64f}, {"none", 0.5f, 0.25f}}) {
    up::Options o = options_for("herzog", {"--gradient-filter", filter});
    o.debug_layers = true;
    const SeqRun r = run_seq(scene, o, T + 1, halve);
    const float* g = r.output.plane("debug.gradient");
    const float* w = r.output.plane("debug.wf");
    ASSERT_TRUE(g && w);
    const std::size_t centre = std::size_t(scene.height / 2) * std::size_t(scene.width) + std::size_t(scene.width / 2);
    EXPECT_NEAR(g[centre], gradient, 1e-4) << filter;
    EXPECT_NEAR(w[centre], wf, 1e-4) << filter;
  }
}

TEST(Upsample, TaauStaticSceneConverges) {
  // A static scene: every pixel is shaded once per k^2 frames and nothing is rectified away, so the accumulated
  // history approaches the full-resolution payload, well below the spatial method's error.
  SyntheticScene scene;
  scene.period = 20.0f;
  const int kk = scene.k * scene.k;
  auto interior = [&](std::size_t i) {
    const int X = int(i % scene.width), Y = int(i / scene.width);
    return X >= scene.k && Y >= scene.k && X < scene.width - scene.k && Y < scene.height - scene.k;
  };
  const SeqRun sp = run_seq(scene, options_for("spatial"), kk);
  const Err es = error(sp.output, sp.frame.reference, interior);
  // Measured: 0.0056 after k^2 frames, 0.0031 after 4 k^2 (spatial 0.0132); the first frame, a Lanczos-2
  // interpolation without the G-buffer, is worse than spatial (0.0217).
  double mean_kk = 0, mean_4kk = 0, max_4kk = 0;
  for (int n : {1, kk, 4 * kk}) {
    const SeqRun r = run_seq(scene, options_for("taau"), n);
    const Err e = error(r.output, r.frame.reference, interior);
    std::printf("taau static (period 20) after %d frames: mean %.5f max %.5f; spatial mean %.5f\n", n, e.mean, e.max,
                es.mean);
    if (n == kk) mean_kk = e.mean;
    if (n == 4 * kk) {
      mean_4kk = e.mean;
      max_4kk = e.max;
    }
  }
  EXPECT_LT(mean_kk, 0.5 * es.mean);
  EXPECT_LT(mean_4kk, 0.3 * es.mean);
  EXPECT_LE(max_4kk, 0.03);
}

TEST(Upsample, DrobotRefreshStaticSceneIsExactAfterKSquaredFrames) {
  SyntheticScene scene;
  const SeqRun r = run_seq(scene, options_for("drobot", {"--mode", "refresh"}), scene.k * scene.k);
  const Err e = error(r.output, r.frame.reference);
  EXPECT_LE(e.max, 1e-6) << "mean " << e.mean;
}

TEST(Upsample, DrobotCacheKeepsConstantBackgroundClean) {
  // Every step (cache, filter, upsampling) is a normalised weighted mean, so a constant background stays
  // constant except where the other surface leaks in. The soft cache test (Listing 7.2: full trust up to
  // 2% relative depth, none from 4%) lets a bilinear history tap mix in at most ~1% of the square, whose
  // payload differs by 0.45: bound 0.01.
  SyntheticScene scene;
  scene.amplitude = 0.0f;
  scene.object = true;
  scene.object_velocity = {1.0f, 0.5f};
  const SeqRun r = run_seq(scene, options_for("drobot"), 20);
  const Err e = error(r.output, r.frame.reference, [&](std::size_t i) {
    return r.frame.object_mask.plane("mask")[i] == 0.0f;
  });
  EXPECT_LE(e.max, 0.01);
  EXPECT_LE(e.mean, 1e-3);
}

TEST(Upsample, SpatialDoesNotBlurAcrossDepthEdges) {
  SyntheticScene scene;
  scene.object = true;
  scene.amplitude = 0.05f;  // nearly flat background: errors come from edges only
  for (const std::string m : {"spatial", "herzog", "drobot"}) {
    const SeqRun r = run_seq(scene, options_for(m), 1);
    // Pixels within k of the square's border, on either side: the payload jumps by ~0.45 there.
    const float* mask = r.frame.object_mask.plane("mask");
    const int W = scene.width;
    auto near_edge = [&](std::size_t i) {
      const int X = int(i % W), Y = int(i / W);
      for (int dy = -scene.k; dy <= scene.k; ++dy)
        for (int dx = -scene.k; dx <= scene.k; ++dx) {
          const int x = std::clamp(X + dx, 0, W - 1), y = std::clamp(Y + dy, 0, scene.height - 1);
          if (mask[std::size_t(y) * W + x] != mask[i]) return true;
        }
      return false;
    };
    const Err e = error(r.output, r.frame.reference, near_edge);
    ASSERT_GT(e.n, 100u);
    // A geometry-blind bilinear filter mixes the two sides (errors up to ~0.4); the depth weight keeps
    // them apart: the remaining error is the smooth payloads' interpolation error.
    EXPECT_LT(e.max, 0.06) << m;
  }
}

TEST(Upsample, NoGhostTrailBehindMovingObject) {
  SyntheticScene scene;
  scene.object = true;
  scene.object_velocity = {1.5f, 0.0f};
  const int frames = 24;
  // Disoccluded region at the last frame: background now, covered by the square in one of the last 8 frames.
  auto region_for = [&](const SyntheticFrame& last) {
    std::vector<char> region(last.object_mask.pixel_count(), 0);
    for (int t = frames - 9; t < frames - 1; ++t) {
      const SyntheticFrame f = make_frame(scene, t);
      for (std::size_t i = 0; i < region.size(); ++i)
        if (f.object_mask.plane("mask")[i] > 0 && last.object_mask.plane("mask")[i] == 0) region[i] = 1;
    }
    return region;
  };
  const SeqRun sp = run_seq(scene, options_for("spatial"), frames);
  const auto region = region_for(sp.frame);
  auto in_region = [&](std::size_t i) { return region[i] != 0; };
  Err es = error(sp.output, sp.frame.reference, in_region);
  ASSERT_GT(es.n, 300u);
  // A method that keeps history fills a disoccluded pixel with that frame's spatial estimate and keeps it (the
  // background is static) until the pattern shades the pixel again, up to k^2 frames later: its error there is
  // spatial's error at the frame of the disocclusion, so the bound takes spatial's worst error in the region over
  // the last k^2 frames, not only at the last one (which depends on where the last frame's samples fell).
  {
    up::Upsampler u(options_for("spatial"));
    for (int t = 0; t < frames; ++t) {
      const SyntheticFrame f = make_frame(scene, t);
      auto out = u.process(f.gbuffer, f.low, kRGB, false);
      ASSERT_TRUE(out.has_value());
      if (t >= frames - scene.k * scene.k) es.max = std::max(es.max, error(**out, f.reference, in_region).max);
    }
  }
  for (const char* variant : {"temporal", "herzog", "drobot-refresh", "herzog-lagged"}) {
    const up::MethodVariant* v = up::find_variant(variant);
    ASSERT_NE(v, nullptr) << variant;
    const up::Options o = options_for(v->method, v->args);
    const SeqRun r = run_seq(scene, o, frames);
    const Err e = error(r.output, r.frame.reference, in_region);
    std::printf("disoccluded region: %s mean %.5f max %.5f (spatial mean %.5f max %.5f)\n", variant, e.mean, e.max,
                es.mean, es.max);
    // A ghost of the square (payload differs by ~0.45) would give errors of that size; the reconstruction
    // there may be no worse than the spatial method's plus a margin for the kernel's flatter shape.
    EXPECT_LE(e.mean, 1.5 * es.mean + 0.005) << variant;
    EXPECT_LT(e.max, 1.5 * es.max + 0.01) << variant;
  }
  // Drobot's low-resolution cache blurs a textured background by design (box + bilinear); with a constant
  // background any error in the disoccluded region is a ghost.
  SyntheticScene flat = scene;
  flat.amplitude = 0.0f;
  const SeqRun dc = run_seq(flat, options_for("drobot"), frames);
  const Err ed = error(dc.output, dc.frame.reference, in_region);
  EXPECT_LT(ed.max, 0.02) << "drobot cache";
}

TEST(Upsample, HistorySurvivesCameraTranslation) {
  SyntheticScene scene;
  scene.camera_velocity = {1.25f, 0.5f};
  const int frames = 2 * scene.k * scene.k;
  for (const std::string m : {"temporal", "herzog"}) {
    const SeqRun r = run_seq(scene, options_for(m), frames);
    // Only the pixels whose previous position is off screen lack history (temporal/core/reproject.h: outside
    // [-0.5, W - 0.5) x [-0.5, H - 0.5) in pixel-index coordinates): with the content moving by (1.25, 0.5) pixels
    // per frame, the last column (x + 1.25 >= W - 0.5) and the last row (y + 0.5 >= H - 0.5): W + H - 1 pixels.
    EXPECT_LE(r.stats.hole_pixels, std::size_t(scene.width + scene.height - 1)) << m;
  }
  const SeqRun sp = run_seq(scene, options_for("spatial"), frames);
  const SeqRun hz = run_seq(scene, options_for("herzog"), frames);
  const Err es = error(sp.output, sp.frame.reference), eh = error(hz.output, hz.frame.reference);
  EXPECT_LT(eh.mean, es.mean) << "herzog " << eh.mean << " spatial " << es.mean;
}

TEST(Upsample, NonFiniteInputNeverEntersHistory) {
  SyntheticScene scene;
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  for (const up::MethodVariant& v : up::method_variants()) {
    {
      const std::string m = v.name;
      const up::Options o = options_for(v.method, v.args);
      const SeqRun r = run_seq(scene, o, 3 * scene.k * scene.k, [&](int t, SyntheticFrame& f, bool&) {
        if (t >= 3 && t < 6) {  // three bad frames, 5 values each
          for (int j = 0; j < 5; ++j) f.low.plane(j % 2 ? "G" : "R")[7 * j + 3] = j % 3 ? nan : inf;
        }
      });
      EXPECT_EQ(r.total_non_finite, 15u) << m;
      EXPECT_TRUE(all_finite(r.output)) << m;
      // Long after the bad frames, the output is as good as without them.
      const SeqRun clean = run_seq(scene, o, 3 * scene.k * scene.k);
      const Err e = error(r.output, clean.output);
      // Exponential histories (herzog, drobot, taau's accumulation) keep a decaying trace of the repaired frames.
      const bool exponential = v.method == "herzog" || v.method == "drobot" || v.method == "taau";
      EXPECT_LE(e.max, exponential ? 0.02 : 1e-6) << m;
    }
  }
}

TEST(Upsample, CameraCutDiscardsHistory) {
  SyntheticScene before;
  before.amplitude = 0.0f;
  SyntheticScene after = before;
  after.payload_offset = -0.3f;  // a different constant payload after the cut
  for (const std::string m : {"temporal", "herzog", "drobot"}) {
    for (int via_metadata = 0; via_metadata < 2; ++via_metadata) {
      up::Upsampler u(options_for(m));
      up::FrameStats stats;
      for (int t = 0; t < 20; ++t) {
        SyntheticFrame f = make_frame(t < 19 ? before : after, t);
        bool cut = false;
        if (t == 19) {
          if (via_metadata)
            f.gbuffer.metadata().camera_cut = true;
          else
            cut = true;
        }
        auto out = u.process(f.gbuffer, f.low, kRGB, cut, &stats);
        ASSERT_TRUE(out.has_value());
        if (t == 19) {
          EXPECT_TRUE(stats.history_reset);
          // Without history every pixel is a convex combination of this frame's constant samples.
          const Err e = error(**out, f.reference);
          EXPECT_LE(e.max, 1e-5) << m << " via metadata " << via_metadata;
        }
      }
    }
  }
  // Control: without the cut the old payload leaks into the output (the test can fail).
  up::Upsampler u(options_for("temporal"));
  Image last;
  SyntheticFrame f;
  for (int t = 0; t < 20; ++t) {
    f = make_frame(t < 19 ? before : after, t);
    last = **u.process(f.gbuffer, f.low, kRGB, false);
  }
  EXPECT_GT(error(last, f.reference).max, 0.1);
}

TEST(Upsample, AntialiasingVariantDownsamples) {
  SyntheticScene scene;
  scene.width = 64;
  scene.height = 48;
  up::Options o = options_for("temporal");
  o.aa_factor = 2;
  const SeqRun r = run_seq(scene, o, scene.k * scene.k);
  ASSERT_EQ(r.output.width(), 32);
  ASSERT_EQ(r.output.height(), 24);
  // Converged temporal result = the full-resolution reference, averaged over 2x2.
  double worst = 0;
  for (const auto& c : kRGB)
    for (int y = 0; y < 24; ++y)
      for (int x = 0; x < 32; ++x) {
        const float* ref = r.frame.reference.plane(c);
        const double mean = 0.25 * (ref[(2 * y) * 64 + 2 * x] + ref[(2 * y) * 64 + 2 * x + 1] +
                                    ref[(2 * y + 1) * 64 + 2 * x] + ref[(2 * y + 1) * 64 + 2 * x + 1]);
        worst = std::max(worst, std::abs(mean - r.output.plane(c)[y * 32 + x]));
      }
  EXPECT_LE(worst, 1e-6);
}

// temporal counts its holes and history hits as w_t = 0 for every pixel, then takes the pixels this frame shaded
// out of whichever count they were in (temporal_impl.inc): its disocclusion mask and its counts must agree on every
// frame, through disocclusions (the moving square), the screen edge (the pan) and the shaded pixels among them.
// The two methods whose shaded pixels (one in k x k) take this frame's sample and are neither hole nor hit: temporal,
// and drobot's refresh mode (Figure 7.12). Both count and mask in loops over the whole row and then correct the shaded
// pixels (temporal_impl.inc; drobot_impl.inc's refresh_row), which this checks frame by frame.
TEST(Upsample, DisocclusionMaskMatchesItsCounts) {
  SyntheticScene scene;
  scene.camera_velocity = {1.25f, 0.5f};
  scene.object = true;
  scene.object_velocity = {2.0f, 0.0f};
  for (const char* method : {"temporal", "drobot"}) {
    up::Options o = std::string(method) == "drobot" ? options_for("drobot", {"--mode", "refresh"}) : options_for(method);
    o.debug_layers = true;
    for (int frames = 1; frames <= 6; ++frames) {
      const SeqRun r = run_seq(scene, o, frames);
      const float* d = r.output.plane("debug.disocclusion");
      ASSERT_NE(d, nullptr) << method;
      std::size_t ones = 0;
      for (std::size_t i = 0; i < r.output.pixel_count(); ++i) ones += d[i] > 0.5f;
      EXPECT_EQ(ones, r.stats.hole_pixels) << method << ", frame " << frames - 1;
      EXPECT_GT(ones, 0u) << method << ", frame " << frames - 1;
      // Every pixel is shaded, a history hit or a hole: exactly one of them (all samples here are finite).
      const std::size_t shaded = std::size_t(scene.width / scene.k) * (scene.height / scene.k);
      EXPECT_EQ(r.stats.hole_pixels + r.stats.history_pixels + shaded, r.output.pixel_count())
          << method << ", frame " << frames - 1;
    }
  }
}

TEST(Upsample, DebugLayers) {
  SyntheticScene scene;
  scene.object = true;
  scene.object_velocity = {2.0f, 0.0f};
  up::Options o = options_for("herzog");
  o.debug_layers = true;
  const SeqRun r = run_seq(scene, o, 6);
  for (const char* name : {"debug.confidence", "debug.disocclusion", "debug.gradient", "debug.wf",
                           "debug.historyWeight", "debug.convergence"})
    EXPECT_TRUE(r.output.has_channel(name)) << name;
  // Disocclusion mask: 1 exactly on the pixels counted as having no history.
  const float* d = r.output.plane("debug.disocclusion");
  std::size_t ones = 0;
  for (std::size_t i = 0; i < r.output.pixel_count(); ++i) ones += d[i] > 0.5f;
  EXPECT_EQ(ones, r.stats.hole_pixels);
  EXPECT_GT(ones, 0u);
  // w_f stays in [0, a]; history weight within its bound 2 k^2 = 32.
  for (std::size_t i = 0; i < r.output.pixel_count(); ++i) {
    ASSERT_GE(r.output.plane("debug.wf")[i], 0.0f);
    ASSERT_LE(r.output.plane("debug.wf")[i], 1.0f);
    ASSERT_LE(r.output.plane("debug.historyWeight")[i], 32.0f);
  }
}

TEST(Upsample, InputErrors) {
  SyntheticScene scene;
  SyntheticFrame f = make_frame(scene, 0);
  up::Upsampler u(options_for("herzog"));
  {
    SyntheticFrame g = f;
    g.gbuffer.remove_channel("motion.X");
    auto out = u.process(g.gbuffer, g.low, kRGB, false, nullptr, {"g.exr", "s.exr"});
    ASSERT_FALSE(out.has_value());
    EXPECT_EQ(out.error().kind, temporal::ErrorKind::Input);
    EXPECT_NE(out.error().message.find("motion"), std::string::npos) << out.error().message;
  }
  {
    SyntheticFrame g = f;
    g.low = g.low.crop({0, 0, g.low.width() - 1, g.low.height()});
    auto out = u.process(g.gbuffer, g.low, kRGB, false);
    ASSERT_FALSE(out.has_value());
    EXPECT_NE(out.error().message.find("full = k * low"), std::string::npos) << out.error().message;
  }
  {
    SyntheticFrame g = f;
    g.low.metadata().jitter_factor.reset();
    auto out = u.process(g.gbuffer, g.low, kRGB, false);
    ASSERT_FALSE(out.has_value());
    EXPECT_NE(out.error().message.find("jitterFactor"), std::string::npos);
  }
  {
    SyntheticFrame g = f;
    g.low.metadata().jitter = glm::vec2(0.1f, 0.0f);  // not on the 4x4 grid
    auto out = u.process(g.gbuffer, g.low, kRGB, false);
    ASSERT_FALSE(out.has_value());
    EXPECT_NE(out.error().message.find("regular"), std::string::npos);
  }
  {
    auto sel = up::select_channels(f.low, "ssao", "s.exr");
    ASSERT_FALSE(sel.has_value());
    EXPECT_EQ(sel.error().file, "s.exr");
  }
}

namespace {
// A 1-pixel albedo checker (0.25 / 0.8, different per channel): detail no upsampler can rebuild from 1/k
// samples, but that --demodulate takes from the full-resolution G-buffer.
float checker_albedo(int X, int Y, int c) { return ((X + Y + c) & 1) ? 0.8f : 0.25f; }

// Adds albedo.R/G/B to the G-buffer and multiplies the low-resolution samples (on full-res pixel
// (k x + sx, k y + sy)) and the reference by it.
void texture_frame(SyntheticFrame& f, int k) {
  const int W = f.gbuffer.width(), H = f.gbuffer.height();
  const glm::ivec2 sub = temporal::regular_subpixel(k, *f.low.metadata().jitter_index);  // conventions "Jitter"
  const int sx = sub.x, sy = sub.y;
  const char* names[3] = {"R", "G", "B"};
  for (int c = 0; c < 3; ++c) {
    float* a = f.gbuffer.add_channel(std::string("albedo.") + names[c]);
    float* ref = f.reference.plane(names[c]);
    for (int Y = 0; Y < H; ++Y)
      for (int X = 0; X < W; ++X) {
        a[std::size_t(Y) * W + X] = checker_albedo(X, Y, c);
        ref[std::size_t(Y) * W + X] *= checker_albedo(X, Y, c);
      }
    float* low = f.low.plane(names[c]);
    for (int y = 0; y < f.low.height(); ++y)
      for (int x = 0; x < f.low.width(); ++x) low[std::size_t(y) * f.low.width() + x] *= checker_albedo(k * x + sx, k * y + sy, c);
  }
}
}  // namespace

TEST(Upsample, DemodulationUpsamplesLightingAndRestoresFullResolutionAlbedo) {
  // The lighting (the untextured synthetic payload) is upsampled, the albedo comes from the G-buffer:
  // the result must be albedo x (the same method run on the untextured payload), exactly up to float
  // rounding, for a method without history (spatial) and one with (herzog: its history stays demodulated).
  SyntheticScene scene;
  scene.camera_velocity = {0.7f, 0.3f};  // history reprojection in play
  for (const std::string m : {"spatial", "herzog"}) {
    up::Options plain = options_for(m), demod = options_for(m);
    demod.demodulate = true;
    up::Upsampler u_plain(plain), u_demod(demod);
    for (int t = 0; t < 6; ++t) {
      SyntheticFrame f = make_frame(scene, t);
      SyntheticFrame g = f;
      texture_frame(g, scene.k);
      auto lit = u_plain.process(f.gbuffer, f.low, kRGB, false);
      auto out = u_demod.process(g.gbuffer, g.low, kRGB, false);
      ASSERT_TRUE(lit && out) << (out ? "" : out.error().message);
      double worst = 0;
      const char* names[3] = {"R", "G", "B"};
      for (int c = 0; c < 3; ++c) {
        const float* L = (*lit)->plane(names[c]);
        const float* O = (*out)->plane(names[c]);
        for (int Y = 0; Y < scene.height; ++Y)
          for (int X = 0; X < scene.width; ++X) {
            const std::size_t i = std::size_t(Y) * scene.width + X;
            worst = std::max(worst, std::abs(double(O[i]) - double(checker_albedo(X, Y, c)) * L[i]));
          }
      }
      EXPECT_LE(worst, 1e-5) << m << " frame " << t;
    }
    // Without demodulation the textured payload loses the 1-pixel checker: far larger error.
    SyntheticFrame f = make_frame(scene, 6), g = f;
    texture_frame(g, scene.k);
    up::Upsampler u_textured(plain), u_demod2(demod);
    auto a = u_textured.process(g.gbuffer, g.low, kRGB, false);
    auto b = u_demod2.process(g.gbuffer, g.low, kRGB, false);
    ASSERT_TRUE(a && b);
    const Err ea = error(**a, g.reference), eb = error(**b, g.reference);
    EXPECT_LT(eb.mean, 0.5 * ea.mean) << m << ": demodulated " << eb.mean << ", textured " << ea.mean;
  }
}

TEST(Upsample, DemodulationInputErrors) {
  SyntheticScene scene;
  SyntheticFrame f = make_frame(scene, 0);
  up::Options o = options_for("spatial");
  o.demodulate = true;
  EXPECT_EQ(up::gbuffer_layers(o).back(), "albedo");
  up::Upsampler u(o);
  // No albedo in the G-buffer: an input error naming the layer.
  auto out = u.process(f.gbuffer, f.low, kRGB, false, nullptr, {"g.exr", "s.exr"});
  ASSERT_FALSE(out.has_value());
  EXPECT_EQ(out.error().kind, temporal::ErrorKind::Input);
  EXPECT_NE(out.error().message.find("albedo"), std::string::npos) << out.error().message;
  // A payload without colour channels cannot be demodulated: a usage error.
  texture_frame(f, scene.k);
  std::copy_n(f.low.plane("R"), f.low.pixel_count(), f.low.add_channel("ssao.Y"));
  const std::vector<std::string> scalar = {"ssao.Y"};
  auto out2 = u.process(f.gbuffer, f.low, scalar, false);
  ASSERT_FALSE(out2.has_value());
  EXPECT_EQ(out2.error().kind, temporal::ErrorKind::Usage);
}

namespace {
// A surface approaching the camera by 10 % of its depth per frame (more than the 5 % of kDepthTolerance): depth.Z
// of frame t is d * 0.9^t where `approaching` holds (d: the scene's depth there), and with `layer` the G-buffer
// gets prevDepth.Z = d * 0.9^(t-1) there (the depth the point had one frame earlier; frame 0: depth.Z) and
// prevDepth.Z = depth.Z elsewhere. The image does not move, so the payload's history stays right: only the
// disocclusion test decides whether it is kept.
void approach(SyntheticFrame& f, int t, bool layer, const std::function<bool(std::size_t)>& approaching) {
  float* z = f.gbuffer.plane("depth.Z");
  float* zw = layer ? f.gbuffer.add_channel("prevDepth.Z") : nullptr;
  for (std::size_t i = 0; i < f.gbuffer.pixel_count(); ++i) {
    const bool a = approaching(i);
    const float d = z[i];
    z[i] = a ? d * std::pow(0.9f, float(t)) : d;
    if (zw) zw[i] = a && t > 0 ? d * std::pow(0.9f, float(t - 1)) : z[i];
  }
}
}  // namespace

TEST(Upsample, WarpedDepthKeepsTheHistoryOfASurfaceApproachingTheCamera) {
  SyntheticScene scene;  // static camera, no object: one plane at depth 50 that approaches
  const int frames = 2 * scene.k * scene.k;
  auto all = [](std::size_t) { return true; };
  for (const std::string m : {"temporal", "herzog"}) {
    auto run_with = [&](bool layer, const std::vector<std::string>& args) {
      return run_seq(scene, options_for(m, args), frames,
                     [&](int t, SyntheticFrame& f, bool&) { approach(f, t, layer, all); });
    };
    const SeqRun with = run_with(true, {});
    const SeqRun without = run_with(false, {});
    const SeqRun ablation = run_with(true, {"--no-depth-velocity"});
    const std::size_t shaded = std::size_t(scene.width / scene.k) * (scene.height / scene.k);
    // With the warped depth every tap passes (|z_exp - z_prev| = 0): no pixel lacks history.
    EXPECT_EQ(with.stats.hole_pixels, 0u) << m;
    EXPECT_GE(with.stats.history_pixels, std::size_t(scene.width) * scene.height - shaded) << m;
    // With the current depth (10 % > 5 %) every history tap is rejected: no pixel has history, and every pixel not
    // shaded this frame is a hole (herzog also counts the shaded ones: it has no history there either).
    EXPECT_EQ(without.stats.history_pixels, 0u) << m;
    EXPECT_GE(without.stats.hole_pixels, std::size_t(scene.width) * scene.height - shaded) << m;
    // --no-depth-velocity ignores the layer: the run without it, bit for bit.
    EXPECT_EQ(ablation.stats.hole_pixels, without.stats.hole_pixels) << m;
    for (const auto& c : kRGB)
      EXPECT_EQ(std::memcmp(ablation.output.plane(c), without.output.plane(c), ablation.output.pixel_count() * 4), 0)
          << m << " " << c;
    // Keeping the history is what makes the result converge: the error is far below the history-less one.
    const Err ew = error(with.output, with.frame.reference), eo = error(without.output, without.frame.reference);
    std::printf("approaching plane: %s mean error %.6f with prevDepth, %.6f without\n", m.c_str(), ew.mean, eo.mean);
    EXPECT_LT(ew.mean, 0.5 * eo.mean) << m;
  }
}

TEST(Upsample, WarpedDepthStillDetectsDisocclusion) {
  // NoGhostTrailBehindMovingObject with the square also approaching the camera (10 % per frame) and a
  // prevDepth.Z layer; the disocclusion test on depth alone (--no-ids, seed 000 Figure 3), so that the warped
  // depth is what decides: the background the square uncovers (warped depth 50) against the square's previous
  // depth (<= 10) is another surface, while the square keeps its own history.
  SyntheticScene scene;
  scene.object = true;
  scene.object_velocity = {1.5f, 0.0f};
  const int frames = 24;
  const SyntheticFrame last = make_frame(scene, frames - 1);
  std::vector<char> region(last.object_mask.pixel_count(), 0);
  for (int t = frames - 9; t < frames - 1; ++t) {
    const SyntheticFrame f = make_frame(scene, t);
    for (std::size_t i = 0; i < region.size(); ++i)
      if (f.object_mask.plane("mask")[i] > 0 && last.object_mask.plane("mask")[i] == 0) region[i] = 1;
  }
  auto in_region = [&](std::size_t i) { return region[i] != 0; };
  auto edit = [&](int t, SyntheticFrame& f, bool&) {
    const float* mask = f.object_mask.plane("mask");
    approach(f, t, true, [&](std::size_t i) { return mask[i] > 0; });
  };
  const SeqRun sp = run_seq(scene, options_for("spatial", {"--no-ids"}), frames, edit);
  Err es = error(sp.output, sp.frame.reference, in_region);
  ASSERT_GT(es.n, 300u);
  {  // spatial's worst error in the region over the last k^2 frames: the fill a history method keeps (NoGhostTrail)
    up::Upsampler u(options_for("spatial", {"--no-ids"}));
    for (int t = 0; t < frames; ++t) {
      SyntheticFrame f = make_frame(scene, t);
      bool cut = false;
      edit(t, f, cut);
      auto out = u.process(f.gbuffer, f.low, kRGB, false);
      ASSERT_TRUE(out.has_value());
      if (t >= frames - scene.k * scene.k) es.max = std::max(es.max, error(**out, f.reference, in_region).max);
    }
  }
  const std::size_t square = std::size_t(scene.object_size) * scene.object_size;
  for (const std::string m : {"temporal", "herzog"}) {
    const SeqRun r = run_seq(scene, options_for(m, {"--no-ids"}), frames, edit);
    const Err e = error(r.output, r.frame.reference, in_region);
    std::printf("approaching square, disoccluded region: %s mean %.5f max %.5f (spatial %.5f %.5f), %zu holes\n",
                m.c_str(), e.mean, e.max, es.mean, es.max, r.stats.hole_pixels);
    // No ghost of the square (payload ~0.45 away) in the uncovered background: the bound of NoGhostTrail.
    EXPECT_LE(e.mean, 1.5 * es.mean + 0.005) << m;
    EXPECT_LT(e.max, 1.5 * es.max + 0.01) << m;
    // The misses are the uncovered strip (1.5 pixels wide, the square's height) and the right and left edges the
    // square's motion takes off screen or uncovers, not the square: far fewer than its area.
    EXPECT_LT(r.stats.hole_pixels, square / 4) << m;
  }
}

// The streaming bound's bytes (Upsampler::streamed_bytes, the benchmark's copy), by hand for 128x64, k = 4, three
// channels: a full plane f = 128 * 64 * 4 = 32768 bytes, a low-resolution one l = f / 16 = 2048. drobot's cache grid
// reads the motion (two planes) and the ids at one pixel in four of every fourth row: every 64-byte line of those
// rows crosses the bus (f / 4 per plane), not the samples' f / 16; with k = 32 the samples lie 128 bytes apart and
// only their own lines cross (2 rows x 4 lines x 64 bytes).
TEST(Upsample, StreamedBytesCountTheLinesEachMethodMoves) {
  const std::size_t f = 32768, l = 2048;
  auto bytes = [](const std::string& method, const std::vector<std::string>& args, int k) {
    return up::Upsampler::streamed_bytes(options_for(method, args), 128, 64, k, 3);
  };
  // depth + N, payload in and out
  EXPECT_EQ(bytes("spatial", {}, 4), 4 * f + 3 * l + 3 * f);
  // + motion, ids, the previous depth and ids read and written, the history read
  EXPECT_EQ(bytes("temporal", {}, 4), 4 * f + 3 * l + 3 * f + 2 * f + f + 4 * f + 3 * f);
  // + h_w read and written
  EXPECT_EQ(bytes("herzog", {}, 4), 4 * f + 3 * l + 3 * f + 2 * f + f + 4 * f + 3 * f + 2 * f);
  // + weight, lock lifetime and lock luminance read and written
  EXPECT_EQ(bytes("taau", {}, 4), 4 * f + 3 * l + 3 * f + 2 * f + f + 4 * f + 3 * f + 6 * f);
  // drobot's refresh mode reads the motion and ids everywhere: as temporal
  EXPECT_EQ(bytes("drobot", {"--mode", "refresh"}, 4), 4 * f + 3 * l + 3 * f + 2 * f + f + 4 * f + 3 * f);
  // cache mode: the grid's motion and ids (3 x f / 4) and the low-resolution cache (values, depth, count, id: 6
  // planes) read and written
  EXPECT_EQ(bytes("drobot", {}, 4), 4 * f + 3 * l + 3 * f + 3 * (f / 4) + 2 * 6 * l);
  // k = 32: a low-resolution plane is f / 1024 = 32 bytes; the grid's 2 rows hold 4 samples each, one line apiece
  EXPECT_EQ(bytes("drobot", {}, 32), 4 * f + 3 * 32 + 3 * f + 3 * (2 * 4 * 64) + 2 * 6 * 32);
}
