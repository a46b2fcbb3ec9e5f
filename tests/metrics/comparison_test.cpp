// The comparison engine on EXR sequences: values against idiff and hand computations, identical sequences,
// masks, error maps, outputs without NaN, and every kind of bad input.
#include "temporal/compare/comparison.h"
#include "temporal/io/exr.h"
#include "temporal/core/image.h"
#include "temporal/metrics/flip.h"

#include "test_support.h"

#include <nlohmann/json.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <initializer_list>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <sstream>

namespace temporal {
namespace {

namespace fs = std::filesystem;

// A 3-channel image with uniform random values in [lo, hi).
Image noise_image(int w, int h, unsigned seed, float lo = 0.0f, float hi = 1.0f) {
  Image img(w, h);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(lo, hi);
  for (const char* c : {"R", "G", "B"}) {
    float* p = img.add_channel(c);
    for (std::size_t i = 0; i < img.pixel_count(); ++i) p[i] = u(rng);
  }
  return img;
}

std::string write_frame(const fs::path& dir, const std::string& name, int frame, const Image& img) {
  char digits[16];
  std::snprintf(digits, sizeof digits, "%04d", frame);
  const auto path = (dir / (name + "." + digits + ".exr")).string();
  EXPECT_TRUE(write_exr(path, img));
  return path;
}

std::string pattern(const fs::path& dir, const std::string& name) { return (dir / (name + ".####.exr")).string(); }

// The comparison of the sequences `tests` ("t" -> dir/t.####.exr) against dir/ref.####.exr, every other setting
// at its default.
ComparisonSetup setup_for(const fs::path& dir, std::initializer_list<const char*> tests) {
  ComparisonSetup setup;
  setup.reference = pattern(dir, "ref");
  for (const char* t : tests) setup.tests.push_back(pattern(dir, t));
  return setup;
}

// "Peak SNR = 24.7712" from idiff's output; NaN when absent.
double idiff_psnr(const std::string& a, const std::string& b) {
  std::string out;
  test::run_command("idiff " + a + " " + b, &out);
  const auto at = out.find("Peak SNR = ");
  if (at == std::string::npos) return NAN;
  return std::atof(out.c_str() + at + 11);
}

bool have_idiff() { return test::run_command("command -v idiff >/dev/null") == 0; }

TEST(Comparison, PsnrMatchesIdiffWithinUnitRange) {
  if (!have_idiff()) GTEST_SKIP() << "idiff (openimageio-tools) is not in PATH";
  const auto dir = test::scratch_dir("comparison-idiff");
  const Image ref = noise_image(48, 32, 1);
  Image test = ref;
  std::mt19937 rng(2);
  std::normal_distribution<float> noise(0.0f, 0.05f);
  for (const char* c : {"R", "G", "B"}) {
    float* p = test.plane(c);
    for (std::size_t i = 0; i < test.pixel_count(); ++i) p[i] = std::clamp(p[i] + noise(rng), 0.0f, 1.0f);
  }
  const auto rp = write_frame(dir, "ref", 0, ref);
  const auto tp = write_frame(dir, "test", 0, test);
  ComparisonSetup setup = setup_for(dir, {"test"});
  auto report = compare_sequences(setup);
  ASSERT_TRUE(report) << report.error().message;
  const double ours = report->sequences[0].frames[0].value("psnr_rgb");
  const double theirs = idiff_psnr(rp, tp);
  ASSERT_FALSE(std::isnan(theirs));
  EXPECT_GT(ours, 20.0);
  EXPECT_NEAR(ours, theirs, 1e-3);  // idiff prints 6 significant digits
}

TEST(Comparison, PeakMaxMatchesIdiffOnHdrData) {
  if (!have_idiff()) GTEST_SKIP() << "idiff (openimageio-tools) is not in PATH";
  const auto dir = test::scratch_dir("comparison-idiff-hdr");
  const Image ref = noise_image(32, 32, 3, 0.0f, 4.0f);
  const Image test = noise_image(32, 32, 4, 0.0f, 4.0f);
  const auto rp = write_frame(dir, "ref", 0, ref);
  const auto tp = write_frame(dir, "test", 0, test);
  ComparisonSetup setup = setup_for(dir, {"test"});
  setup.peak_from_data = true;
  auto report = compare_sequences(setup);
  ASSERT_TRUE(report);
  const auto& f = report->sequences[0].frames[0];
  EXPECT_GT(f.peak, 3.9);
  EXPECT_NEAR(f.value("psnr_rgb"), idiff_psnr(rp, tp), 1e-3);
  // The default fixed peak of 1 gives 20 log10(peak) dB less.
  setup.peak_from_data = false;
  auto fixed = compare_sequences(setup);
  ASSERT_TRUE(fixed);
  EXPECT_NEAR(f.value("psnr_rgb") - fixed->sequences[0].frames[0].value("psnr_rgb"), 20.0 * std::log10(f.peak), 1e-6);
}

TEST(Comparison, HandComputedPsnrAndFlicker) {
  // Reference constant 0.5; test = 0.5 + 0.1 on R only at even frames and 0.5 - 0.1 at odd frames.
  // PSNR(RGB): MSE = 0.01 / 3 -> 10 log10(300) = 24.7712 dB. Luminance error 0.02126: PSNR_Y = -20 log10(0.02126).
  // Flicker: d = -0.2 * 0.2126 (then +) at every pixel -> RMS 0.04252.
  const auto dir = test::scratch_dir("comparison-hand");
  for (int f = 0; f < 3; ++f) {
    Image ref = test::make_image(16, 12, {"R", "G", "B"}, 0.5f);
    Image t = ref;
    std::fill(t.plane("R"), t.plane("R") + t.pixel_count(), f % 2 == 0 ? 0.6f : 0.4f);
    write_frame(dir, "ref", f, ref);
    write_frame(dir, "t", f, t);
  }
  ComparisonSetup setup = setup_for(dir, {"t"});
  auto report = compare_sequences(setup);
  ASSERT_TRUE(report) << report.error().message;
  const auto& frames = report->sequences[0].frames;
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_NEAR(frames[0].value("psnr_rgb"), 10.0 * std::log10(300.0), 1e-4);
  EXPECT_NEAR(frames[0].value("psnr_y"), -20.0 * std::log10(0.1 * 0.2126), 1e-4);
  EXPECT_TRUE(std::isnan(frames[0].value("flicker")));  // no previous frame
  EXPECT_NEAR(frames[1].value("flicker"), 0.2 * 0.2126, 1e-6);
  EXPECT_NEAR(frames[2].value("flicker"), 0.2 * 0.2126, 1e-6);
  // Constant images: SSIM is the luminance term of Wang et al. eq. 13 for Y_test vs Y_ref = 0.5.
  const double yt = 0.5 + 0.1 * 0.2126, yr = 0.5, c1 = 1e-4;
  EXPECT_NEAR(frames[0].value("ssim"), (2 * yt * yr + c1) / (yt * yt + yr * yr + c1), 1e-6);
}

TEST(Comparison, IdenticalSequencesGiveInfinitePsnrZeroFlickerAndNoNan) {
  const auto dir = test::scratch_dir("comparison-identical");
  for (int f = 0; f < 3; ++f) {
    const Image img = noise_image(20, 16, unsigned(10 + f));
    write_frame(dir, "ref", f, img);
    write_frame(dir, "same", f, img);
  }
  ComparisonSetup setup = setup_for(dir, {"same"});
  auto report = compare_sequences(setup);
  ASSERT_TRUE(report);
  for (const auto& f : report->sequences[0].frames) {
    EXPECT_TRUE(std::isinf(f.value("psnr_rgb")) && f.value("psnr_rgb") > 0);
    EXPECT_TRUE(std::isinf(f.value("psnr_y")) && f.value("psnr_y") > 0);
    EXPECT_NEAR(f.value("ssim"), 1.0, 1e-9);
    if (f.frame > 0) {
      EXPECT_EQ(f.value("flicker"), 0.0);
    }
  }
  const auto csv = (dir / "m.csv").string(), json = (dir / "m.json").string();
  ASSERT_TRUE(write_comparison_csv(*report, csv));
  ASSERT_TRUE(write_comparison_json(*report, {}, {}, "compare test", "", json));
  const auto csv_text = test::read_file(csv);
  EXPECT_EQ(csv_text.find("nan"), std::string::npos);
  EXPECT_NE(csv_text.find("1,same,inf,inf,1,0,"), std::string::npos) << csv_text;
  const auto j = nlohmann::json::parse(test::read_file(json));  // throws (fails the test) if invalid
  const auto& s = j["sequences"][0];
  EXPECT_EQ(s["psnr_rgb"]["mean"], "inf");
  EXPECT_EQ(s["flicker"]["mean"], 0.0);
  EXPECT_EQ(s["flicker"]["frames"], 2);
  EXPECT_EQ(test::read_file(json).find("NaN"), std::string::npos);
}

TEST(Comparison, MaskSplitsInsideAndOutside) {
  const auto dir = test::scratch_dir("comparison-mask");
  for (int f = 0; f < 2; ++f) {
    Image ref = noise_image(24, 16, unsigned(f + 1));
    Image t = ref;
    float* mask = t.add_channel("debug.disocclusion");
    float* r = t.plane("R");
    for (int y = 0; y < 16; ++y)
      for (int x = 12; x < 24; ++x) {  // right half: inside the mask, where the only error is
        mask[y * 24 + x] = 1.0f;
        r[y * 24 + x] += 0.1f;
      }
    write_frame(dir, "ref", f, ref);
    write_frame(dir, "t", f, t);
  }
  ComparisonSetup setup = setup_for(dir, {"t"});
  setup.mask = "debug.disocclusion";
  auto report = compare_sequences(setup);
  ASSERT_TRUE(report) << report.error().message;
  EXPECT_EQ(report->sequences[0].mask_source, "test");
  const auto& f = report->sequences[0].frames[1];
  EXPECT_TRUE(f.has_mask);
  EXPECT_NEAR(f.mask_fraction, 0.5, 1e-12);
  const MetricSample& psnr = *f.sample("psnr_rgb");
  const MetricSample& ssim = *f.sample("ssim");
  const MetricSample& flicker = *f.sample("flicker");
  EXPECT_TRUE(std::isinf(psnr.outside));
  EXPECT_NEAR(psnr.inside, 10.0 * std::log10(300.0), 1e-3);     // MSE 0.01 / 3 inside
  EXPECT_NEAR(psnr.values[0], 10.0 * std::log10(600.0), 1e-3);  // half the pixels: MSE halves
  // Windows centred outside but reaching into the mask see some error; those inside all do.
  EXPECT_GT(ssim.outside, 0.999);
  EXPECT_LT(ssim.outside, 1.0);
  EXPECT_LT(ssim.inside, 1.0 - 1e-4);
  ASSERT_FALSE(std::isnan(flicker.inside) || std::isnan(flicker.outside));
  EXPECT_NEAR(flicker.inside, 0.0, 1e-6);  // a stable error does not flicker
}

TEST(Comparison, MotionCompensatedFlickerWithGbuffer) {
  // A pattern scrolling right 2 px per frame with a stable error on the surface: zero flicker when the G-buffer's
  // motion (-2, 0) is used, clearly non-zero without it.
  const auto dir = test::scratch_dir("comparison-motion");
  const int w = 40, h = 12;
  std::mt19937 rng(4);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<float> tex(80), err(80);
  for (auto& v : tex) v = u(rng);
  for (auto& v : err) v = 0.2f * u(rng) - 0.1f;
  for (int f = 0; f < 3; ++f) {
    Image ref(w, h), t(w, h), g(w, h);
    for (const char* c : {"R", "G", "B"}) {
      float* rp = ref.add_channel(c);
      float* tp = t.add_channel(c);
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
          const int s = x - 2 * f + 10;
          rp[y * w + x] = tex[std::size_t(s)];
          tp[y * w + x] = tex[std::size_t(s)] + err[std::size_t(s)];
        }
    }
    g.add_channel("motion.X", f == 0 ? 0.0f : -2.0f);
    g.add_channel("motion.Y", 0.0f);
    write_frame(dir, "ref", f, ref);
    write_frame(dir, "t", f, t);
    write_frame(dir, "g", f, g);
  }
  ComparisonSetup setup = setup_for(dir, {"t"});
  setup.gbuffer = pattern(dir, "g");
  auto comp = compare_sequences(setup);
  ASSERT_TRUE(comp) << comp.error().message;
  EXPECT_TRUE(comp->motion_compensated);
  EXPECT_NEAR(comp->sequences[0].frames[2].value("flicker"), 0.0, 1e-6);
  EXPECT_EQ(comp->sequences[0].frames[2].sample("flicker")->count, std::size_t((w - 2) * h));
  setup.gbuffer.clear();
  auto plain = compare_sequences(setup);
  ASSERT_TRUE(plain);
  EXPECT_GT(plain->sequences[0].frames[2].value("flicker"), 0.02);
}

TEST(Comparison, ReferenceLayerAndCameraCut) {
  // The reference keeps its colour in `reference.R,G,B` (render-gbuffer's payload layer); the test is bare RGB.
  // Frame 1 of the reference is a camera cut: no flicker value there, one again at frame 2.
  const auto dir = test::scratch_dir("comparison-reflayer");
  for (int f = 0; f < 3; ++f) {
    Image ref(16, 16), t = test::make_image(16, 16, {"R", "G", "B"}, 0.5f);
    for (const char* c : {"reference.B", "reference.G", "reference.R"}) ref.add_channel(c, 0.5f);
    std::fill(ref.plane("reference.R"), ref.plane("reference.R") + ref.pixel_count(), 0.4f);
    if (f == 1) ref.metadata().camera_cut = true;
    write_frame(dir, "ref", f, ref);
    write_frame(dir, "t", f, t);
  }
  ComparisonSetup setup = setup_for(dir, {"t"});
  setup.reference_layer = "reference";
  auto report = compare_sequences(setup);
  ASSERT_TRUE(report) << report.error().message;
  EXPECT_EQ(report->reference_channels, (std::vector<std::string>{"reference.R", "reference.G", "reference.B"}));
  const auto& frames = report->sequences[0].frames;
  EXPECT_NEAR(frames[0].value("psnr_rgb"), 10.0 * std::log10(300.0), 1e-4);  // R differs by 0.1, G and B agree
  EXPECT_TRUE(std::isnan(frames[1].value("flicker")));
  EXPECT_EQ(frames[2].value("flicker"), 0.0);
  // A layer with another channel count is an input error naming both layers.
  setup.reference_layer.clear();
  setup.layer = "rgb";
  setup.reference_layer = "motion";
  for (int f = 0; f < 3; ++f) {
    Image ref(16, 16);
    ref.add_channel("motion.X");
    ref.add_channel("motion.Y");
    write_frame(dir, "ref", f, ref);
  }
  auto bad = compare_sequences(setup);
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().kind, ErrorKind::Input);
  EXPECT_NE(bad.error().message.find("channels"), std::string::npos) << bad.error().message;
}

TEST(Comparison, NonFinitePixelsAreCountedAndExcluded) {
  const auto dir = test::scratch_dir("comparison-nan");
  for (int f = 0; f < 2; ++f) {
    Image ref = test::make_image(16, 16, {"R", "G", "B"}, 0.5f);
    Image t = ref;
    std::fill(t.plane("G"), t.plane("G") + t.pixel_count(), 0.6f);
    t.plane("R")[3] = NAN;
    t.plane("B")[40] = INFINITY;
    write_frame(dir, "ref", f, ref);
    write_frame(dir, "t", f, t);
  }
  ComparisonSetup setup = setup_for(dir, {"t"});
  setup.error_maps = (dir / "maps").string();
  int warnings = 0;
  ComparisonHooks hooks;
  hooks.warning = [&](const std::string& file, const std::string& text) {
    ++warnings;
    EXPECT_NE(file.find("t.000"), std::string::npos);
    EXPECT_NE(text.find("2 pixels"), std::string::npos) << text;
  };
  auto report = compare_sequences(setup, hooks);
  ASSERT_TRUE(report);
  EXPECT_EQ(warnings, 2);
  const auto& f = report->sequences[0].frames[1];
  EXPECT_EQ(f.nonfinite_test, 2u);
  EXPECT_EQ(f.valid_pixels, 254u);
  EXPECT_NEAR(f.value("psnr_rgb"), 10.0 * std::log10(300.0), 1e-4);  // the remaining pixels: error 0.1 on G
  EXPECT_TRUE(std::isfinite(f.value("ssim")));
  EXPECT_NEAR(f.value("flicker"), 0.0, 1e-7);
  // The error map marks the excluded pixels and holds no NaN.
  auto map = read_exr((dir / "maps" / "t.0001.exr").string());
  ASSERT_TRUE(map) << map.error().message;
  EXPECT_EQ(map->plane("error.invalid")[3], 1.0f);
  EXPECT_EQ(map->plane("error.R")[3], 0.0f);
  EXPECT_NEAR(map->plane("error.G")[0], 0.1f, 1e-6);
  EXPECT_EQ(count_non_finite({map->plane("error.ssim"), map->pixel_count()}), 0u);
  EXPECT_EQ(map->metadata().frame.value_or(-1), 1);
}

TEST(Comparison, ThresholdsJudgeMeanOrWorstFrame) {
  ComparisonReport report;
  SequenceReport s;
  s.name = "taa";
  for (int f = 0; f < 3; ++f) {
    FrameMetrics m;
    m.frame = f;
    m.ensure_sample("psnr_rgb").values = {f == 1 ? 25.0 : 35.0};  // mean 31.67, worst 25
    m.ensure_sample("ssim").values = {0.9};
    m.ensure_sample("flicker").values = {f > 0 ? 0.01 * f : kNoValue};  // mean 0.015, worst 0.02
    s.frames.push_back(m);
  }
  report.sequences.push_back(s);
  report.metrics = {"psnr_rgb", "psnr_y", "ssim", "flicker"};
  Thresholds th;
  th.limits["psnr_rgb"] = 30.0;
  EXPECT_TRUE(check_thresholds(report, th).empty());
  th.worst_frame = true;
  auto fails = check_thresholds(report, th);
  ASSERT_EQ(fails.size(), 1u);
  EXPECT_EQ(fails[0].metric, "psnr_rgb");
  EXPECT_EQ(fails[0].message(), "taa: psnr_rgb 25 dB < limit 30 dB");
  EXPECT_EQ(fails[0].value, 25.0);
  th = {};
  th.limits["flicker"] = 0.012;
  th.limits["ssim"] = 0.95;
  fails = check_thresholds(report, th);
  ASSERT_EQ(fails.size(), 2u);
  EXPECT_EQ(fails[0].metric, "ssim");  // registry order
  EXPECT_NEAR(fails[1].value, 0.015, 1e-12);
  EXPECT_EQ(fails[1].message(), "taa: flicker 0.015 > limit 0.012");
}

// --- The metric registry and FLIP in the engine ---------------------------------------------------------

TEST(MetricRegistry, EntriesAreCompleteAndUnique) {
  const auto& registry = metric_registry();
  ASSERT_GE(registry.size(), 5u);
  // The four historical metrics first, in their CSV order.
  const char* historical[] = {"psnr_rgb", "psnr_y", "ssim", "flicker"};
  std::set<std::string> names, columns, options;
  for (std::size_t i = 0; i < registry.size(); ++i) {
    const auto& d = registry[i];
    if (i < 4) {
      EXPECT_EQ(d.name, historical[i]);
    }
    EXPECT_EQ(d.historical_csv, i < 4) << d.name;
    EXPECT_TRUE(names.insert(d.name).second) << d.name;
    ASSERT_FALSE(d.columns.empty()) << d.name;
    for (const auto& c : d.columns) EXPECT_TRUE(columns.insert(c.csv).second) << c.csv;
    for (const auto& c : d.mask_columns) EXPECT_TRUE(columns.insert(c).second) << c;
    if (!d.threshold_option.empty()) {
      EXPECT_TRUE(options.insert(d.threshold_option).second) << d.threshold_option;
    }
    EXPECT_TRUE(d.make) << d.name;
    EXPECT_EQ(find_metric(d.name), &d);
  }
  EXPECT_EQ(find_metric("no such metric"), nullptr);
  EXPECT_EQ(options, (std::set<std::string>{"psnr", "ssim", "flicker", "flip", "psnr-latency"}));
  // FLIP and the latency-aware PSNR only when asked for.
  ComparisonSetup setup;
  EXPECT_EQ(enabled_metrics(setup).size(), 4u);
  setup.flip = FlipMode::Ldr;
  EXPECT_EQ(enabled_metrics(setup).back()->name, "flip");
  setup.flip = FlipMode::Off;
  setup.latency_aware = true;
  EXPECT_EQ(enabled_metrics(setup).size(), 5u);
  EXPECT_EQ(enabled_metrics(setup).back()->name, "psnr_latency");
}

// Frames 0-1 of a reference and a noisy test (with a mask layer in the test), for the FLIP engine tests.
ComparisonSetup flip_sequences(const fs::path& dir) {
  for (int f = 0; f < 2; ++f) {
    Image ref = noise_image(40, 32, unsigned(30 + f), 0.0f, 1.2f);
    Image t = ref;
    std::mt19937 rng(unsigned(40 + f));
    std::normal_distribution<float> noise(0.0f, 0.05f);
    for (const char* c : {"R", "G", "B"}) {
      float* p = t.plane(c);
      for (std::size_t i = 0; i < t.pixel_count(); ++i) p[i] += noise(rng);
    }
    float* m = t.add_channel("debug.mask");
    for (std::size_t i = 0; i < t.pixel_count(); ++i) m[i] = (i % 40) < 20 ? 1.0f : 0.0f;
    write_frame(dir, "ref", f, ref);
    write_frame(dir, "t", f, t);
  }
  return setup_for(dir, {"t"});
}

TEST(Comparison, FlipIsTheLibraryFlipOfTheClampedFrames) {
  const auto dir = test::scratch_dir("comparison-flip");
  ComparisonSetup setup = flip_sequences(dir);
  setup.flip = FlipMode::Ldr;
  setup.flip_options.pixels_per_degree = 40.0;
  setup.error_maps = (dir / "maps").string();
  setup.mask = "debug.mask";
  auto report = compare_sequences(setup);
  ASSERT_TRUE(report) << report.error().message;
  EXPECT_EQ(report->metrics.back(), "flip");
  // The same frame through the library: LDR-FLIP of the linear values clamped to [0, 1] (the display-encoded
  // frame, linearised again), at 40 pixels per degree.
  auto ref = read_exr((dir / "ref.0001.exr").string());
  auto test = read_exr((dir / "t.0001.exr").string());
  ASSERT_TRUE(ref && test);
  FlipOptions o;
  o.pixels_per_degree = 40.0;
  o.ldr_input = FlipLdrInput::Linear;
  std::vector<float> map(ref->pixel_count());
  ASSERT_TRUE(FlipEvaluator(o).ldr({test->plane("R"), test->plane("G"), test->plane("B")},
                                   {ref->plane("R"), ref->plane("G"), ref->plane("B")}, 40, 32, nullptr, map.data()));
  const FlipStats want = flip_statistics(map);
  const auto& f = report->sequences[0].frames[1];
  const MetricSample& flip = *f.sample("flip");
  ASSERT_EQ(flip.values.size(), 4u);
  EXPECT_DOUBLE_EQ(flip.values[0], want.mean);
  EXPECT_DOUBLE_EQ(flip.values[1], want.weighted_median);
  EXPECT_DOUBLE_EQ(flip.values[2], want.weighted_quartile_1);
  EXPECT_DOUBLE_EQ(flip.values[3], want.weighted_quartile_3);
  EXPECT_GT(want.mean, 0.01);
  // Inside / outside the mask (left half of each row): plain means of the map.
  double in = 0, out = 0;
  for (std::size_t i = 0; i < map.size(); ++i) ((i % 40) < 20 ? in : out) += map[i];
  EXPECT_NEAR(flip.inside, in / (map.size() / 2), 1e-12);
  EXPECT_NEAR(flip.outside, out / (map.size() / 2), 1e-12);
  // The map is the error.flip layer.
  auto maps = read_exr((dir / "maps" / "t.0001.exr").string());
  ASSERT_TRUE(maps) << maps.error().message;
  ASSERT_NE(maps->plane("error.flip"), nullptr);
  for (std::size_t i = 0; i < map.size(); ++i) ASSERT_EQ(maps->plane("error.flip")[i], map[i]) << i;
  // CSV: the historical columns first, FLIP's after the mask columns; JSON: the summary with the quartiles.
  const auto csv = (dir / "m.csv").string(), json = (dir / "m.json").string();
  ASSERT_TRUE(write_comparison_csv(*report, csv));
  ASSERT_TRUE(write_comparison_json(*report, {}, {}, "compare test", "", json));
  const auto header = test::read_file(csv).substr(0, test::read_file(csv).find('\n'));
  EXPECT_EQ(header,
            "frame,sequence,psnr_rgb_db,psnr_y_db,ssim,flicker,mse_rgb,peak,valid_pixels,nonfinite_test,"
            "nonfinite_reference,compute_ms,metrics_ms,mask_fraction,psnr_rgb_in_db,psnr_rgb_out_db,psnr_y_in_db,"
            "psnr_y_out_db,ssim_in,ssim_out,flicker_in,flicker_out,flip,flip_weighted_median,flip_weighted_q1,"
            "flip_weighted_q3,flip_in,flip_out");
  const auto j = nlohmann::json::parse(test::read_file(json));
  EXPECT_EQ(j["flip"]["mode"], "ldr");
  EXPECT_EQ(j["flip"]["pixels_per_degree"], 40.0);
  const auto& js = j["sequences"][0]["flip"];
  for (const char* key : {"mean", "min", "max", "weighted_median", "weighted_quartile_1", "weighted_quartile_3"})
    EXPECT_TRUE(js.contains(key)) << key;
  EXPECT_EQ(js["frames"], 2);
  EXPECT_TRUE(j["sequences"][0]["inside_mask"].contains("flip"));
  EXPECT_TRUE(j["thresholds"].contains("flip"));
}

TEST(Comparison, FlipOffLeavesTheOutputsAsTheyWere) {
  const auto dir = test::scratch_dir("comparison-flip-off");
  const ComparisonSetup setup = flip_sequences(dir);
  auto report = compare_sequences(setup);
  ASSERT_TRUE(report);
  EXPECT_EQ(report->metrics, (std::vector<std::string>{"psnr_rgb", "psnr_y", "ssim", "flicker"}));
  const auto csv = (dir / "m.csv").string(), json = (dir / "m.json").string();
  ASSERT_TRUE(write_comparison_csv(*report, csv));
  ASSERT_TRUE(write_comparison_json(*report, {}, {}, "compare test", "", json));
  EXPECT_EQ(test::read_file(csv).substr(0, test::read_file(csv).find('\n')),
            "frame,sequence,psnr_rgb_db,psnr_y_db,ssim,flicker,mse_rgb,peak,valid_pixels,nonfinite_test,"
            "nonfinite_reference,compute_ms,metrics_ms");
  const auto j = nlohmann::json::parse(test::read_file(json));
  EXPECT_FALSE(j.contains("flip"));
  EXPECT_FALSE(j["sequences"][0].contains("flip"));
  EXPECT_EQ(j["thresholds"].size(), 4u);  // psnr_rgb, ssim, flicker, judged_on
  // The table's header as compare printed it before the registry (printf with fixed widths), then (issue 24) the
  // pooled PSNRs after compute_ms, so that the columns before keep their places.
  char header[200];
  std::snprintf(header, sizeof header, "%-20s %7s %10s %10s %9s %11s %11s %15s %13s\n", "sequence", "frames",
                "psnr_rgb", "psnr_y", "ssim", "flicker", "compute_ms", "psnr_rgb_pooled", "psnr_y_pooled");
  const std::string table = summary_table(*report);
  EXPECT_EQ(table.rfind(header, 0), 0u) << table;
}

TEST(Comparison, HdrFlipAndItsErrors) {
  const auto dir = test::scratch_dir("comparison-flip-hdr");
  ComparisonSetup setup = flip_sequences(dir);
  setup.flip = FlipMode::Hdr;
  auto report = compare_sequences(setup);
  ASSERT_TRUE(report) << report.error().message;
  const double v = report->sequences[0].frames[0].value("flip");
  EXPECT_GT(v, 0.0);
  EXPECT_LT(v, 1.0);
  // A threshold on FLIP needs FLIP; a bad viewing condition and a layer FLIP cannot read are errors.
  Thresholds th;
  th.limits["flip"] = 0.1;
  EXPECT_TRUE(check_threshold_setup(setup, th));
  setup.flip = FlipMode::Off;
  const Status off = check_threshold_setup(setup, th);
  ASSERT_FALSE(off);
  EXPECT_EQ(off.error().kind, ErrorKind::Usage);
  EXPECT_NE(off.error().message.find("--flip ldr"), std::string::npos) << off.error().message;
  setup.flip = FlipMode::Ldr;
  setup.flip_options.pixels_per_degree = -1.0;
  auto bad_ppd = compare_sequences(setup);
  ASSERT_FALSE(bad_ppd);
  EXPECT_EQ(bad_ppd.error().kind, ErrorKind::Usage);
  setup.flip_options.pixels_per_degree = 30.0;
  for (int f = 0; f < 2; ++f) {
    Image two(16, 16);
    two.add_channel("motion.X", 0.5f);
    two.add_channel("motion.Y", 0.25f);
    write_frame(dir, "two", f, two);
  }
  setup.reference = pattern(dir, "two");
  setup.tests = {pattern(dir, "two")};
  setup.layer = "motion";
  auto two = compare_sequences(setup);
  ASSERT_FALSE(two);
  EXPECT_EQ(two.error().kind, ErrorKind::Input);
  EXPECT_NE(two.error().file.find("two.0000.exr"), std::string::npos) << two.error().file;
  EXPECT_NE(two.error().message.find("2 channels"), std::string::npos) << two.error().message;
}

TEST(Comparison, SequenceNames) {
  EXPECT_EQ(sequence_name("out/taa.####.exr"), "taa");
  EXPECT_EQ(sequence_name("phlm_%04d.exr"), "phlm");
  EXPECT_EQ(sequence_name("single.exr"), "single");
}

// --- Bad input: a clear error of the right kind, never a crash -------------------------------------------

class BadInput : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::scratch_dir(std::string("comparison-bad-") + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    for (int f = 0; f < 2; ++f) {
      write_frame(dir_, "ref", f, noise_image(16, 16, unsigned(f)));
      write_frame(dir_, "t", f, noise_image(16, 16, unsigned(f + 5)));
    }
    setup_.reference = pattern(dir_, "ref");
    setup_.tests = {pattern(dir_, "t")};
  }
  Error run_expecting_error() {
    auto r = compare_sequences(setup_);
    EXPECT_FALSE(r) << "expected an error";
    return r ? Error{} : r.error();
  }
  fs::path dir_;
  ComparisonSetup setup_;
};

TEST_F(BadInput, TruncatedExr) {
  const auto path = dir_ / "t.0001.exr";
  const auto size = fs::file_size(path);
  fs::resize_file(path, size / 2);
  const auto e = run_expecting_error();
  EXPECT_EQ(e.kind, ErrorKind::Input);
  EXPECT_NE(e.file.find("t.0001.exr"), std::string::npos);
}

TEST_F(BadInput, CorruptExr) {
  std::ofstream((dir_ / "ref.0000.exr").string(), std::ios::binary | std::ios::trunc) << "not an EXR at all";
  const auto e = run_expecting_error();
  EXPECT_EQ(e.kind, ErrorKind::Input);
  EXPECT_NE(e.file.find("ref.0000.exr"), std::string::npos);
}

TEST_F(BadInput, MissingLayer) {
  setup_.layer = "albedo";
  const auto e = run_expecting_error();
  EXPECT_EQ(e.kind, ErrorKind::Input);
  EXPECT_NE(e.message.find("albedo"), std::string::npos) << e.message;
}

TEST_F(BadInput, MissingMaskLayer) {
  setup_.mask = "debug.disocclusion";
  const auto e = run_expecting_error();
  EXPECT_EQ(e.kind, ErrorKind::Input);
  EXPECT_NE(e.message.find("mask"), std::string::npos) << e.message;
}

TEST_F(BadInput, MismatchedSizes) {
  write_frame(dir_, "t", 1, noise_image(20, 16, 9));
  const auto e = run_expecting_error();
  EXPECT_EQ(e.kind, ErrorKind::Input);
  EXPECT_NE(e.message.find("20x16"), std::string::npos) << e.message;
}

TEST_F(BadInput, MissingTestFrame) {
  fs::remove(dir_ / "t.0001.exr");
  const auto e = run_expecting_error();
  EXPECT_EQ(e.kind, ErrorKind::Input);
  EXPECT_NE(e.file.find("t.0001.exr"), std::string::npos) << e.file << ": " << e.message;
}

TEST_F(BadInput, EmptySequence) {
  setup_.reference = pattern(dir_, "nothing");
  const auto e = run_expecting_error();
  EXPECT_EQ(e.kind, ErrorKind::Input);
}

TEST_F(BadInput, TooSmallForSsim) {
  write_frame(dir_, "tiny", 0, noise_image(8, 8, 1));
  setup_.reference = pattern(dir_, "tiny");
  setup_.tests = {pattern(dir_, "tiny")};
  const auto e = run_expecting_error();
  EXPECT_EQ(e.kind, ErrorKind::Input);
}

TEST_F(BadInput, NamesCountMismatchIsUsage) {
  setup_.names = {"a", "b"};
  EXPECT_EQ(run_expecting_error().kind, ErrorKind::Usage);
}

}  // namespace
}  // namespace temporal

namespace temporal {
namespace {

// --peak's text: a positive finite number, or `max` (idiff's per-frame rule); anything else is a usage error.
TEST(SetPeak, NumbersMaxAndRefusals) {
  ComparisonSetup s;
  ASSERT_TRUE(set_peak("2.5", s));
  EXPECT_DOUBLE_EQ(s.peak, 2.5);
  EXPECT_FALSE(s.peak_from_data);
  ASSERT_TRUE(set_peak("max", s));
  EXPECT_TRUE(s.peak_from_data);
  ASSERT_TRUE(set_peak("1e3", s));
  EXPECT_DOUBLE_EQ(s.peak, 1000.0);
  EXPECT_FALSE(s.peak_from_data);
  for (const char* bad : {"0", "-1", "nan", "inf", "1x", "", "MAX"}) {
    const Status st = set_peak(bad, s);
    ASSERT_FALSE(st) << bad;
    EXPECT_EQ(st.error().kind, ErrorKind::Usage) << bad;
    EXPECT_NE(st.error().message.find("--peak"), std::string::npos) << bad;
  }
}

// --- Regions and pooled PSNR (issue 24) ---------------------------------------------------------------------

// 4x4, frame 1 against frame 0, one pixel of each kind the classification knows (S static, M moving, D
// disoccluded):
//   D S M D     (0,0): motion -1 px in x fetches off screen; column 2: motion -1 px (same surface, a hit);
//   S S M D     column 3: rows 0-1 change material id, rows 2-3 depth 1 -> 2 (beyond the 5 % tolerance): the
//   S S M D     depth/id test of temporal/core/reproject.h fails;
//   S M M D     (1,3): still, but the reference's luminance changed by 0.5 > tolerance.
TEST(Regions, HandClassifiedFourByFour) {
  const int w = 4, h = 4;
  const std::size_t n = 16;
  std::vector<float> mx(n, 0.0f), my(n, 0.0f), z(n, 1.0f), pz(n, 1.0f), y(n, 0.3f), py(n, 0.3f);
  std::vector<std::uint32_t> id(n, 1), pid(n, 1);
  mx[0] = -1.0f;
  for (int r = 0; r < h; ++r) mx[std::size_t(r * w + 2)] = -1.0f;
  id[3] = id[7] = 2;
  z[11] = z[15] = 2.0f;
  y[13] = 0.8f;
  RegionInputs in;
  in.width = w;
  in.height = h;
  in.motion_x = mx.data();
  in.motion_y = my.data();
  in.depth = z.data();
  in.id = id.data();
  in.previous_depth = pz.data();
  in.previous_id = pid.data();
  in.reference_y = y.data();
  in.previous_reference_y = py.data();
  RegionOptions o;
  o.static_frames = 2;
  std::vector<std::uint16_t> still(n, 0);
  std::vector<std::uint8_t> labels(n, 99);
  // Frame 0: no previous frame, so no history anywhere.
  in.has_previous = false;
  classify_regions(in, o, still, labels);
  for (std::size_t i = 0; i < n; ++i) EXPECT_EQ(labels[i], kRegionDisoccluded) << i;
  const char* expected = "DSMD" "SSMD" "SSMD" "SMMD";
  auto code = [](std::uint8_t l) { return l == kRegionStatic ? 'S' : l == kRegionMoving ? 'M' : 'D'; };
  // Frame 1: the still pixels have been still for 1 frame, fewer than --static-frames 2: moving.
  in.has_previous = true;
  y[13] = 0.8f;
  classify_regions(in, o, still, labels);
  for (std::size_t i = 0; i < n; ++i) EXPECT_EQ(code(labels[i]), expected[i] == 'S' ? 'M' : expected[i]) << i;
  // Frame 2, same inputs but the reference of (1,3) unchanged since frame 1 (still 1 there): the others reach 2.
  py[13] = 0.8f;
  classify_regions(in, o, still, labels);
  for (std::size_t i = 0; i < n; ++i) EXPECT_EQ(code(labels[i]), expected[i]) << i;
  EXPECT_EQ(still[13], 1);
  EXPECT_EQ(still[5], 2);
  // A camera cut (no history) resets every count.
  in.has_previous = false;
  classify_regions(in, o, still, labels);
  EXPECT_EQ(still[5], 0);
}

TEST(Regions, PooledPsnrIsThePsnrOfThePooledSquaredError) {
  // Two frames at 20 dB (MSE 0.01) and 10 dB (MSE 0.1), equal pixels: pooled MSE 0.055 -> 12.5964 dB, while the
  // mean of the frames' PSNRs is 15 dB.
  const std::vector<double> p = {20.0, 10.0}, w = {100.0, 100.0};
  EXPECT_NEAR(pooled_psnr(p, w), -10.0 * std::log10(0.055), 1e-12);
  // Weights are pixel counts: 300 pixels at MSE 0.01 and 100 at 0.1 -> (3 + 10) / 400.
  EXPECT_NEAR(pooled_psnr(p, std::vector<double>{300.0, 100.0}), -10.0 * std::log10(13.0 / 400.0), 1e-12);
  // The firefly case: 19 frames at 40 dB and one at 15 dB. Mean of PSNRs 38.75 dB; pooled 27.76 dB.
  std::vector<double> ff(20, 40.0), fw(20, 1.0);
  ff[7] = 15.0;
  EXPECT_NEAR(pooled_psnr(ff, fw), -10.0 * std::log10((19 * 1e-4 + std::pow(10.0, -1.5)) / 20.0), 1e-9);
  // +inf frames add no error, NaN frames and empty weights are left out, one -inf frame makes it -inf.
  EXPECT_NEAR(pooled_psnr(std::vector<double>{20.0, INFINITY, NAN}, std::vector<double>{1.0, 1.0, 1.0}),
              -10.0 * std::log10(0.005), 1e-12);
  EXPECT_TRUE(std::isinf(pooled_psnr(std::vector<double>{INFINITY}, std::vector<double>{1.0})));
  EXPECT_EQ(pooled_psnr(std::vector<double>{20.0, -INFINITY}, std::vector<double>{1.0, 1.0}), -INFINITY);
  EXPECT_TRUE(std::isnan(pooled_psnr(std::vector<double>{20.0}, std::vector<double>{0.0})));
  // The interval holds the value; a constant series has a zero-width interval; the paired difference of a series with
  // itself is 0.
  const MeanInterval m = bootstrap_pooled_psnr(ff, fw);
  EXPECT_EQ(m.count, 20u);
  EXPECT_DOUBLE_EQ(m.mean, pooled_psnr(ff, fw));
  EXPECT_LE(m.ci.low, m.mean);
  EXPECT_GE(m.ci.high, m.mean);
  EXPECT_LT(m.ci.low, m.ci.high);
  const MeanInterval c = bootstrap_pooled_psnr(std::vector<double>(10, 30.0), std::vector<double>(10, 5.0));
  EXPECT_NEAR(c.ci.low, 30.0, 1e-9);
  EXPECT_NEAR(c.ci.high, 30.0, 1e-9);
  const MeanInterval d = bootstrap_pooled_psnr_difference(ff, fw, ff, fw);
  EXPECT_EQ(d.mean, 0.0);
  EXPECT_EQ(d.ci.low, 0.0);
  EXPECT_EQ(d.ci.high, 0.0);
}

// 12x12 (the SSIM window needs 11x11), two frames, reference 0.5 everywhere and unchanged; the G-buffer's depth is
// 1 and ids 1, except at frame 1 columns 8-11 change id (disoccluded) and columns 4-7 move by -1 px in x (a hit:
// moving); columns 0-3 are static (--static-frames 1). The test errs by 0.1 on every channel at frame 0 (all
// disoccluded: no previous frame), and at frame 1 by 0.1 / 0.2 / 0.4 in the static / moving / disoccluded columns.
//   frame 1 PSNR: static 20 dB, moving 10 log10(1/0.04) = 13.979 dB, disoccluded 10 log10(1/0.16) = 7.959 dB,
//                 all: MSE (0.01 + 0.04 + 0.16) / 3 = 0.07 -> 11.549 dB; frame 0: 20 dB (all and disoccluded).
//   psnr_rgb (mean of frames) = (20 + 11.549) / 2 = 15.775 dB; psnr_rgb_pooled: MSE (0.01 + 0.07) / 2 = 0.04 ->
//   13.979 dB; disoccluded pooled: (144 x 0.01 + 48 x 0.16) / 192 = 0.0475 -> 13.233 dB.
TEST(Regions, PerRegionAndPooledValuesOnAHandMadeSequence) {
  const auto dir = test::scratch_dir("comparison-regions");
  const int w = 12, h = 12;
  for (int f = 0; f < 2; ++f) {
    Image ref(w, h), t(w, h), g(w, h);
    for (const char* c : {"R", "G", "B"}) {
      ref.add_channel(c, 0.5f);
      float* tp = t.add_channel(c);
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) tp[y * w + x] = 0.5f + (f == 0 ? 0.1f : x < 4 ? 0.1f : x < 8 ? 0.2f : 0.4f);
    }
    float* mx = g.add_channel("motion.X", 0.0f);
    g.add_channel("motion.Y", 0.0f);
    g.add_channel("depth.Z", 1.0f);
    std::uint32_t* id = g.add_uint_channel("id", 1);
    float* inside = g.add_channel("half", 0.0f);  // a mask for --mask beside the regions: the left half
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w / 2; ++x) inside[y * w + x] = 1.0f;
    if (f == 1)
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
          if (x >= 4 && x < 8) mx[y * w + x] = -1.0f;
          if (x >= 8) id[y * w + x] = 2;
        }
    write_frame(dir, "ref", f, ref);
    write_frame(dir, "t", f, t);
    write_frame(dir, "g", f, g);
  }
  // A second test, better everywhere by a constant 0.05: paired differences per region.
  for (int f = 0; f < 2; ++f) {
    Image u(w, h);
    for (const char* c : {"R", "G", "B"}) u.add_channel(c, 0.55f);
    write_frame(dir, "u", f, u);
  }
  ComparisonSetup setup = setup_for(dir, {"t", "u"});
  setup.gbuffer = pattern(dir, "g");
  setup.regions = true;
  setup.region_options.static_frames = 1;
  auto rep = compare_sequences(setup);
  ASSERT_TRUE(rep) << rep.error().message;
  const SequenceReport& s = rep->sequences[0];
  ASSERT_EQ(s.frames.size(), 2u);
  const FrameMetrics& f0 = s.frames[0];
  const FrameMetrics& f1 = s.frames[1];
  EXPECT_EQ(f0.region_pixels, (std::array<std::size_t, 3>{0, 0, 144}));
  EXPECT_EQ(f1.region_pixels, (std::array<std::size_t, 3>{48, 48, 48}));
  const auto* p0 = f0.sample("psnr_rgb");
  const auto* p1 = f1.sample("psnr_rgb");
  EXPECT_TRUE(std::isnan(p0->regions[kRegionStatic]));
  EXPECT_NEAR(p0->regions[kRegionDisoccluded], 20.0, 1e-5);
  EXPECT_NEAR(p1->regions[kRegionStatic], 20.0, 1e-5);
  EXPECT_NEAR(p1->regions[kRegionMoving], -10.0 * std::log10(0.04), 1e-5);
  EXPECT_NEAR(p1->regions[kRegionDisoccluded], -10.0 * std::log10(0.16), 1e-5);
  EXPECT_NEAR(p1->values[0], -10.0 * std::log10(0.07), 1e-5);
  // Luminance errs by the same amounts (R = G = B): the same values.
  EXPECT_NEAR(f1.sample("psnr_y")->regions[kRegionMoving], -10.0 * std::log10(0.04), 1e-4);
  // Mean of frames against pooled, whole frame and per region.
  EXPECT_NEAR(summarize(s, "psnr_rgb").mean, (20.0 - 10.0 * std::log10(0.07)) / 2.0, 1e-5);
  EXPECT_NEAR(pooled_summary(s, "psnr_rgb", kAllRegions, {}).mean, -10.0 * std::log10(0.04), 1e-5);
  EXPECT_NEAR(pooled_summary(s, "psnr_rgb", kRegionDisoccluded, {}).mean, -10.0 * std::log10(0.0475), 1e-5);
  EXPECT_NEAR(pooled_summary(s, "psnr_rgb", kRegionStatic, {}).mean, 20.0, 1e-5);
  // The pooled error of `all` is the share-weighted combination of the regions' pooled errors, shares summing to 1.
  double share = 0.0, combined = 0.0;
  for (int r = 0; r < kRegionCount; ++r) {
    share += region_share(s, r);
    combined += region_share(s, r) * std::pow(10.0, -pooled_summary(s, "psnr_rgb", r, {}).mean / 10.0);
  }
  EXPECT_NEAR(share, 1.0, 1e-12);
  // (The whole-frame kernel sums float differences, the region sums double ones: 1e-7 dB apart.)
  EXPECT_NEAR(-10.0 * std::log10(combined), pooled_summary(s, "psnr_rgb", kAllRegions, {}).mean, 1e-6);
  // SSIM per region: by window centre. At 12x12 the only full 11x11 windows are centred at x, y = 5, 6, in the
  // moving columns: SSIM has a value there and none in the other regions, and it is the whole frame's.
  const auto* ss = f1.sample("ssim");
  ASSERT_NE(ss, nullptr);
  EXPECT_TRUE(std::isnan(ss->regions[kRegionStatic]));
  EXPECT_TRUE(std::isnan(ss->regions[kRegionDisoccluded]));
  EXPECT_NEAR(ss->regions[kRegionMoving], ss->values[0], 1e-12);
  // Flicker: none where disoccluded (no history there), a value where moving.
  const auto* fl = f1.sample("flicker");
  EXPECT_TRUE(std::isnan(fl->regions[kRegionDisoccluded]));
  EXPECT_FALSE(std::isnan(fl->regions[kRegionMoving]));

  // CSV: a region column, one row per region, region rows read back into the same values (merge).
  const auto csv_path = (dir / "r.csv").string();
  ASSERT_TRUE(write_comparison_csv(*rep, csv_path));
  const auto csv = test::read_file(csv_path);
  EXPECT_EQ(csv.rfind("frame,sequence,region,region_share,psnr_rgb_db,", 0), 0u) << csv;
  EXPECT_NE(csv.find("\n1,t,static,0.3333333333333333,"), std::string::npos) << csv;
  EXPECT_NE(csv.find("\n1,t,all,1,"), std::string::npos) << csv;
  std::size_t rows = 0;
  for (char c : csv) rows += c == '\n';
  EXPECT_EQ(rows, 1u + 2 * 2 * 4);
  auto back = read_comparison_csv(csv_path);
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_TRUE(back->regions);
  ASSERT_EQ(back->sequences[0].frames.size(), 2u);
  EXPECT_EQ(back->sequences[0].frames[1].region_pixels, f1.region_pixels);
  EXPECT_EQ(back->sequences[0].frames[1].sample("psnr_rgb")->regions, p1->regions);
  EXPECT_EQ(back->sequences[0].frames[1].value("psnr_rgb"), p1->values[0]);

  // JSON: pooled beside the mean, regions with shares, per-region paired differences.
  const auto json_path = (dir / "r.json").string();
  ASSERT_TRUE(write_comparison_json(*rep, {}, {}, "test", "", json_path));
  const auto j = nlohmann::json::parse(test::read_file(json_path));
  EXPECT_EQ(j["regions"]["static_frames"], 1);
  const auto& js = j["sequences"][0];
  EXPECT_NEAR(js["psnr_rgb_pooled"]["value"].get<double>(), -10.0 * std::log10(0.04), 1e-5);
  EXPECT_EQ(js["psnr_rgb_pooled"]["ci95"].size(), 2u);
  EXPECT_NEAR(js["regions"]["moving"]["share"].get<double>(), 48.0 / 288.0, 1e-12);
  EXPECT_NEAR(js["regions"]["moving"]["psnr_rgb"]["mean"].get<double>(), -10.0 * std::log10(0.04), 1e-5);
  EXPECT_EQ(js["regions"]["moving"]["psnr_rgb"]["frames"], 1);
  EXPECT_NEAR(js["regions"]["disoccluded"]["psnr_rgb_pooled"]["value"].get<double>(), -10.0 * std::log10(0.0475), 1e-5);
  bool region_pair = false, pooled_pair = false;
  for (const auto& p : j["paired"]) {
    if (p["region"] == "disoccluded" && p["metric"] == "psnr_rgb") {
      region_pair = true;  // t errs by 0.4 there, u by 0.05: t is worse
      EXPECT_LT(p["mean_difference"].get<double>(), 0.0);
    }
    if (p["region"] == "all" && p["metric"] == "psnr_rgb_pooled") {
      pooled_pair = true;
      EXPECT_NEAR(p["difference"].get<double>(), -10.0 * std::log10(0.04) - -10.0 * std::log10(0.0025), 1e-4);
    }
  }
  EXPECT_TRUE(region_pair);
  EXPECT_TRUE(pooled_pair);
  // The summary table has a pooled column and a region table.
  const std::string table = summary_table(*rep);
  EXPECT_NE(table.find("psnr_rgb_pooled"), std::string::npos) << table;
  EXPECT_NE(table.find("disoccluded"), std::string::npos) << table;

  // --mask keeps working beside the regions: its columns hold values on the `all` rows, nothing on region rows,
  // and the region values do not change.
  setup.mask = "half";
  auto masked = compare_sequences(setup);
  ASSERT_TRUE(masked) << masked.error().message;
  const FrameMetrics& m1 = masked->sequences[0].frames[1];
  EXPECT_EQ(m1.sample("psnr_rgb")->regions, p1->regions);
  EXPECT_NEAR(m1.mask_fraction, 0.5, 1e-12);
  EXPECT_NEAR(m1.sample("psnr_rgb")->inside, -10.0 * std::log10((0.01 + 0.04 / 2.0) / 1.5), 1e-5);  // columns 0-5
  ASSERT_TRUE(write_comparison_csv(*masked, csv_path));
  std::istringstream masked_csv(test::read_file(csv_path));
  std::string header, all_row, static_row;
  std::getline(masked_csv, header);
  std::getline(masked_csv, all_row);     // frame 0, t, all
  for (int k = 0; k < 9; ++k) std::getline(masked_csv, static_row);  // past frame 0 (2 x 4 rows): frame 1, t, static
  auto column = [](const std::string& line, std::size_t k) {
    std::stringstream in(line);
    std::string cell;
    for (std::size_t i = 0; i <= k && std::getline(in, cell, ','); ++i) {}
    return cell;
  };
  std::size_t in_column = 0;
  {
    std::stringstream in(header);
    std::string cell;
    for (std::size_t i = 0; std::getline(in, cell, ','); ++i)
      if (cell == "psnr_rgb_in_db") in_column = i;
  }
  ASSERT_GT(in_column, 0u) << header;
  EXPECT_EQ(static_row.rfind("1,t,static,", 0), 0u) << static_row;
  EXPECT_FALSE(column(all_row, in_column).empty()) << all_row;
  EXPECT_TRUE(column(static_row, in_column).empty()) << static_row;
}

TEST(Regions, NeedTheGbufferWithDepthAndIds) {
  const auto dir = test::scratch_dir("comparison-regions-errors");
  for (int f = 0; f < 2; ++f) {
    write_frame(dir, "ref", f, noise_image(12, 12, 1));
    write_frame(dir, "t", f, noise_image(12, 12, 2));
    Image g(12, 12);
    g.add_channel("motion.X", 0.0f);
    g.add_channel("motion.Y", 0.0f);
    write_frame(dir, "g", f, g);
  }
  ComparisonSetup setup = setup_for(dir, {"t"});
  setup.regions = true;
  auto none = compare_sequences(setup);
  ASSERT_FALSE(none);
  EXPECT_EQ(none.error().kind, ErrorKind::Usage);
  EXPECT_NE(none.error().message.find("--gbuffer"), std::string::npos) << none.error().message;
  setup.gbuffer = pattern(dir, "g");
  auto flat = compare_sequences(setup);
  ASSERT_FALSE(flat);
  EXPECT_EQ(flat.error().kind, ErrorKind::Input);
  EXPECT_NE(flat.error().message.find("depth.Z"), std::string::npos) << flat.error().message;
  setup.region_options.static_frames = 0;
  auto zero = compare_sequences(setup);
  ASSERT_FALSE(zero);
  EXPECT_EQ(zero.error().kind, ErrorKind::Usage);
}

}  // namespace
}  // namespace temporal
