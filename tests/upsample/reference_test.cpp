// Every method and named variant of the stage's table against its plain implementation (reference.h: the header
// formulas, one pixel at a time) on small random sequences: random geometry with depth edges and material ids,
// aligned (integer) and random (fractional, gathered) motion, NaN samples and motion, a camera cut, factors 4 and 3
// (odd width). The fast kernels round differently (polynomial kernel powers, reordered sums, FMA), so the
// comparison has explicit tolerances; it passes on any CPU, unlike a bit-exact golden file.
#include "reference.h"
#include "synthetic.h"

#include "temporal/core/parallel.h"
#include "temporal/upsample/methods.h"
#include "temporal/upsample/upsample.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <cstring>
#include <cstdio>
#include <limits>
#include <random>

namespace up = temporal::upsample;
using temporal::Image;

namespace {

struct Frame {
  Image gbuffer, low;
};

// A random sequence of `count` frames at W x H, factor k. Three rectangles (ids 2-4, depth ~10) move over a sloped
// background (id 1, depth 20-26); the top half of the background moves by an integer pixel per frame (aligned
// history taps), the bottom half by random fractional amounts per pixel (gathered taps); normals and payload are
// random. Frame 4 has NaN and 1e20 payload samples and NaN motion, frame `count` / 2 is a camera cut.
std::vector<Frame> random_sequence(int W, int H, int k, int count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u01(0.0f, 1.0f), jitter(-0.15f, 0.15f), frac(-1.5f, 1.5f);
  struct Rect {
    float x, y, w, h, vx, vy, z;
  };
  std::vector<Rect> rects;
  for (int r = 0; r < 3; ++r)
    rects.push_back({u01(rng) * W * 0.6f, u01(rng) * H * 0.6f, 6 + u01(rng) * W * 0.3f, 6 + u01(rng) * H * 0.3f,
                     frac(rng), frac(rng), 8.0f + 2.0f * float(r)});
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::vector<Frame> frames;
  for (int t = 0; t < count; ++t) {
    Frame f;
    f.gbuffer = Image(W, H);
    float* z = f.gbuffer.add_channel("depth.Z");
    float* n[3] = {f.gbuffer.add_channel("N.X"), f.gbuffer.add_channel("N.Y"), f.gbuffer.add_channel("N.Z")};
    float* mx = f.gbuffer.add_channel("motion.X");
    float* my = f.gbuffer.add_channel("motion.Y");
    std::uint32_t* id = f.gbuffer.add_uint_channel("id");
    for (int Y = 0; Y < H; ++Y)
      for (int X = 0; X < W; ++X) {
        const std::size_t i = std::size_t(Y) * W + X;
        z[i] = 20.0f + 0.08f * float(X) + 0.05f * float(Y);
        id[i] = 1;
        mx[i] = Y < H / 2 ? 1.0f : frac(rng);
        my[i] = Y < H / 2 ? 0.0f : frac(rng);
        for (std::size_t r = 0; r < rects.size(); ++r) {
          const Rect& R = rects[r];
          const float px = float(X) + 0.5f - R.vx * float(t), py = float(Y) + 0.5f - R.vy * float(t);
          if (px >= R.x && px < R.x + R.w && py >= R.y && py < R.y + R.h) {
            z[i] = R.z + 0.01f * float(X);
            id[i] = std::uint32_t(2 + r);
            mx[i] = -R.vx;
            my[i] = -R.vy;
          }
        }
        const float a = jitter(rng), b = jitter(rng), len = std::sqrt(a * a + b * b + 1.0f);
        n[0][i] = a / len;
        n[1][i] = b / len;
        n[2][i] = 1.0f / len;
      }
    if (t == 4) {
      mx[std::size_t(H - 3) * W + 5] = nan;
      my[std::size_t(H / 2) * W + 7] = nan;
    }
    auto& gm = f.gbuffer.metadata();
    gm.near_clip = 0.1f;
    gm.far_clip = 100.0f;
    gm.frame = t;
    gm.camera_cut = t == count / 2;
    const int lw = W / k, lh = H / k, index = t % (k * k);
    f.low = Image(lw, lh);
    for (const char* c : {"R", "G", "B"}) {
      float* p = f.low.add_channel(c);
      for (int j = 0; j < lw * lh; ++j) p[j] = u01(rng);
    }
    if (t == 4) {
      for (int j = 0; j < 3; ++j) f.low.plane("G")[std::size_t(7 * j + 2)] = nan;
      // and samples past kMaxSampleMagnitude (temporal/core/image.h), which are no samples either
      for (int j = 0; j < 3; ++j) f.low.plane("R")[std::size_t(11 * j + 4)] = 1e20f;
    }
    auto& lm = f.low.metadata();
    lm = gm;
    lm.camera_cut.reset();
    lm.jitter_factor = k;
    lm.jitter_index = index;
    frames.push_back(std::move(f));
  }
  return frames;
}

// Largest difference between the production and the plain result over every frame and channel; NaN anywhere
// counts as infinite.
double max_difference(const up::Options& o, const std::vector<Frame>& frames,
                      const std::vector<std::string>& rgb = {"R", "G", "B"}) {
  up::Upsampler fast(o);
  temporal::test::PlainUpsampler plain(o);
  double worst = 0;
  for (const Frame& f : frames) {
    auto a = fast.process(f.gbuffer, f.low, rgb, false);
    EXPECT_TRUE(a.has_value()) << (a ? "" : a.error().message);
    if (!a) return std::numeric_limits<double>::infinity();
    const Image b = plain.process(f.gbuffer, f.low, rgb, f.gbuffer.metadata().camera_cut.value_or(false));
    for (const auto& c : rgb)
      for (std::size_t i = 0; i < b.pixel_count(); ++i) {
        const double d = std::abs(double((*a)->plane(c)[i]) - double(b.plane(c)[i]));
        worst = std::max(worst, std::isnan(d) ? std::numeric_limits<double>::infinity() : d);
      }
  }
  return worst;
}

// Payload values are in [0, 1]. The fast kernels differ from the plain loops by float rounding only: reordered
// sums and products, FMA, kernel_exp2 for herzog's kernel powers (relative error < 2e-7), pow(dot, 32) by squaring and
// a division instead of a reciprocal in drobot's Listing 7.1. Measured on this project's AVX-512 machine (GCC 12,
// -march=native): at most 3.6e-7 for spatial, temporal and herzog, 3.4e-6 for taau (its Lanczos-2 sums cancel
// between the negative lobes), and 5.2e-6 for drobot, whose Listing 7.2
// confidence multiplies depth roundings by IN_ConvergenceTime (50); the tolerances leave a factor of 10-30 for other
// CPUs and compilers. A wrong weight, tap or rule gives differences of 1e-3 to 1 (the payload is random): drobot's
// fetch before it used the reprojection module differed from this plain version by up to 0.94.
double tolerance(const std::string& method) {
  if (method == "drobot") return 5e-5;
  return 1e-5;
}

}  // namespace

TEST(UpsampleReference, EveryMethodMatchesItsPlainImplementation) {
  struct Size {
    int W, H, k;
  };
  for (const Size s : {Size{48, 40, 4}, Size{45, 36, 3}}) {
    const auto frames = random_sequence(s.W, s.H, s.k, 14, unsigned(s.k));
    for (const up::MethodVariant& v : up::method_variants()) {
      auto o = up::make_options(v.method, v.args);
      ASSERT_TRUE(o.has_value()) << v.name;
      const double d = max_difference(*o, frames);
      std::printf("%-22s %dx%d k=%d: max |fast - plain| = %.3g (tolerance %.0e)\n", v.name.c_str(), s.W, s.H, s.k, d,
                  tolerance(v.method));
      EXPECT_LE(d, tolerance(v.method)) << v.name << " at " << s.W << "x" << s.H << ", k = " << s.k;
    }
  }
}

TEST(UpsampleReference, NoIdsAndOtherParameters) {
  // The options that change which taps count and how the kernel falls off, on one size.
  const auto frames = random_sequence(48, 40, 4, 10, 7);
  const std::vector<std::vector<std::string>> runs = {
      {"temporal", "--no-ids"},
      {"herzog", "--no-ids", "--depth-tolerance", "0.2"},
      {"herzog", "--kernel-gamma", "9", "--max-kernel-gamma", "6", "--min-kernel-gamma", "1", "--a", "0.8"},
      {"herzog", "--gradient-scale", "4", "--gradient-mip-level", "3", "--max-history-weight", "10"},
      {"herzog", "--fallback", "flat", "--min-kernel-gamma", "0.5"},
      {"drobot", "--cache-point", "--miss-threshold", "0.05", "--max-frames", "8"},
      {"drobot", "--mode", "refresh", "--no-ids", "--depth-only"},
      {"taau", "--no-locks", "--box-scale", "2", "--motion-accumulation", "0.6", "--history", "bilinear"},
      {"taau", "--no-ids", "--lock-luma-change", "0.3", "--depth-tolerance", "0.2"},
  };
  for (const auto& run : runs) {
    auto o = up::make_options(run[0], std::vector<std::string>(run.begin() + 1, run.end()));
    ASSERT_TRUE(o.has_value()) << o.error().message;
    std::string name;
    for (const auto& a : run) name += a + " ";
    const double d = max_difference(*o, frames);
    std::printf("%s: max |fast - plain| = %.3g\n", name.c_str(), d);
    EXPECT_LE(d, tolerance(run[0])) << name;
  }
}

// More than four payload channels: the history methods' one-pass fetch (reproject_gather_row) takes up to four
// planes and falls back to the reprojection's two steps above (herzog fetches h_w and the channels: six planes from
// five channels), and herzog's eq. 6 and drobot's Listings 7.1 and 7.3 run their channels in groups of three. R, G,
// B and two more random channels (the gradient's norm then mixes the luminance with the other layers), every history
// method and drobot's refresh mode, against the plain loops.
TEST(UpsampleReference, FiveChannels) {
  auto frames = random_sequence(48, 40, 4, 10, 11);
  const std::vector<std::string> five = {"R", "G", "B", "U", "V"};
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u01(0.0f, 1.0f);
  for (Frame& f : frames)
    for (const char* c : {"U", "V"}) {
      float* p = f.low.add_channel(c);
      for (std::size_t j = 0; j < f.low.pixel_count(); ++j) p[j] = u01(rng);
    }
  const std::vector<std::vector<std::string>> runs = {
      {"temporal"}, {"herzog"}, {"drobot"}, {"drobot", "--mode", "refresh"}};
  for (const auto& run : runs) {
    auto o = up::make_options(run[0], std::vector<std::string>(run.begin() + 1, run.end()));
    ASSERT_TRUE(o.has_value()) << o.error().message;
    std::string name;
    for (const auto& a : run) name += a + " ";
    const double d = max_difference(*o, frames, five);
    std::printf("%s(5 channels): max |fast - plain| = %.3g\n", name.c_str(), d);
    EXPECT_LE(d, tolerance(run[0])) << name;
  }
}

TEST(UpsampleReference, SyntheticScenes) {
  // The smooth scenes of upsample_golden (a pan with a moving square, per-frame G-buffers) at k = 4, 3 (odd width)
  // and 2 (herzog's gradient at full/4 with an integer mip level), every method and variant.
  temporal::test::SyntheticScene b;
  b.width = 96;
  b.height = 64;
  b.camera_velocity = {0.75f, -0.5f};
  b.object = true;
  b.object_start = {20.0f, 15.0f};
  b.object_velocity = {2.5f, 1.5f};
  b.object_size = 30;
  temporal::test::SyntheticScene k3 = b, k2 = b;
  k3.width = 99;
  k3.height = 75;
  k3.k = 3;
  k2.k = 2;
  for (const auto& [scene, extra] : {std::pair{b, std::vector<std::string>{}}, std::pair{k3, std::vector<std::string>{}},
                                     std::pair{k2, std::vector<std::string>{"--gradient-scale", "4",
                                                                           "--gradient-mip-level", "3"}}}) {
    std::vector<Frame> frames;
    for (int t = 1; t <= 12; ++t) {
      auto f = temporal::test::make_frame(scene, t);
      frames.push_back({std::move(f.gbuffer), std::move(f.low)});
    }
    for (const up::MethodVariant& v : up::method_variants()) {
      std::vector<std::string> args = v.args;
      args.insert(args.end(), extra.begin(), extra.end());
      auto o = up::make_options(v.method, args);
      ASSERT_TRUE(o.has_value()) << v.name;
      const double d = max_difference(*o, frames);
      std::printf("%-22s %dx%d k=%d: max |fast - plain| = %.3g\n", v.name.c_str(), scene.width, scene.height, scene.k,
                  d);
      EXPECT_LE(d, tolerance(v.method)) << v.name << " at k = " << scene.k;
    }
  }
}

TEST(UpsampleReference, DrobotWavefrontBands) {
  // drobot's cache mode runs a frame as a wavefront in bands of 32 cache rows (run_cache: the cache update, Listing
  // 7.3's vertical pass 4 rows behind it and the full rows behind that), the rows around each edge between two bands
  // once both bands got far enough, or, next to a band shorter than twice the filter's reach, in two later phases;
  // the sizes above have at most 32 cache rows, one band. Tall frames: 69 cache rows (on one thread bands of 32, 32
  // and 5, the last shorter than the filter's reach on both sides), 33 (a last band of one row) and 37 at k = 3. A
  // full row upsampled before its cache rows were filtered, or an edge row left out, reads the frame before last's
  // cache (the ping-pong buffer) and differs by 1e-3 to 1.
  struct Size {
    int W, H, k;
  };
  for (const Size s : {Size{40, 276, 4}, Size{40, 132, 4}, Size{36, 111, 3}}) {
    const auto frames = random_sequence(s.W, s.H, s.k, 8, unsigned(s.H));
    auto o = up::make_options("drobot", {});
    ASSERT_TRUE(o.has_value()) << o.error().message;
    const double d = max_difference(*o, frames);
    std::printf("drobot %dx%d k=%d: max |fast - plain| = %.3g\n", s.W, s.H, s.k, d);
    EXPECT_LE(d, tolerance("drobot")) << s.W << "x" << s.H << ", k = " << s.k;
  }
}

TEST(UpsampleReference, ChunksFollowTheThreadCount) {
  // herzog walks chunks of gradient rows and drobot's cache mode bands of cache rows in parallel, sized by the task
  // arena's threads (temporal::rows_per_chunk: 64 gradient rows, 32 cache rows, down to 16 where fewer would leave
  // threads idle; both then shrink towards the end on several threads, guided self-scheduling, the threads taking
  // them in order from a counter). At 40x276, k = 4 (138 gradient rows, 69 cache rows) one thread gets chunks of 64
  // and bands of 32; two threads herzog chunks of 36, 28, 20, 16, 16, 16 and 6 rows, drobot bands of 18, 16, 16, 16
  // and 3 (its last edge, next to a band shorter than the filter's reach, left to the later phases; the others run
  // between bands, by whichever thread is free); three threads bands of 16, 16, 16, 16 and 5; sixteen threads chunks
  // and bands of 16, so other rows fall on the edges. The output must be the same bits, and the small bands must
  // still match the plain implementation.
  const auto frames = random_sequence(40, 276, 4, 8, 276u);
  const std::vector<std::string> rgb = {"R", "G", "B"};
  for (const char* method : {"herzog", "drobot"}) {
    auto o = up::make_options(method, {});
    ASSERT_TRUE(o.has_value()) << o.error().message;
    auto run = [&](int threads) {
      std::vector<Image> out;
      // The arena's concurrency counts only up to TBB's allowed parallelism (the machine's cores by default): raised,
      // so that the chunks are those of `threads` threads on a 2-core machine too.
      const temporal::ThreadLimit limit(threads);
      tbb::task_arena arena(threads);
      arena.execute([&] {
        up::Upsampler u(*o);
        for (const Frame& f : frames) {
          auto a = u.process(f.gbuffer, f.low, rgb, false);
          ASSERT_TRUE(a.has_value()) << a.error().message;
          out.push_back(**a);
        }
      });
      return out;
    };
    const std::vector<Image> one = run(1), two = run(2), three = run(3), sixteen = run(16);
    ASSERT_EQ(one.size(), frames.size());
    ASSERT_EQ(two.size(), frames.size());
    ASSERT_EQ(three.size(), frames.size());
    ASSERT_EQ(sixteen.size(), frames.size());
    for (std::size_t t = 0; t < frames.size(); ++t)
      for (const auto& c : rgb) {
        EXPECT_EQ(std::memcmp(one[t].plane(c), two[t].plane(c), one[t].pixel_count() * sizeof(float)), 0)
            << method << " frame " << t << " " << c << " (2 threads)";
        EXPECT_EQ(std::memcmp(one[t].plane(c), three[t].plane(c), one[t].pixel_count() * sizeof(float)), 0)
            << method << " frame " << t << " " << c << " (3 threads)";
        EXPECT_EQ(std::memcmp(one[t].plane(c), sixteen[t].plane(c), one[t].pixel_count() * sizeof(float)), 0)
            << method << " frame " << t << " " << c << " (16 threads)";
      }
    double d = 0;
    {
      const temporal::ThreadLimit limit(16);
      tbb::task_arena(16).execute([&] { d = max_difference(*o, frames); });
    }
    std::printf("%s 40x276 k=4, 16 threads: max |fast - plain| = %.3g\n", method, d);
    EXPECT_LE(d, tolerance(method)) << method;
  }
}
