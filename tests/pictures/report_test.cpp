// compare's pictures, charts and HTML report, end to end on small sequences: the engine's frame observer, each
// plot defect of issue 13 (formats by extension, axis ranges, titles, names, what the speed chart plots, the
// progress line), `compare --png` and `compare --report` as files, and the report rendered by headless Chromium
// (screenshot not blank, every picture loaded, tables, charts, contact sheet, FLIP maps and the video present).
#include "temporal/io/exr.h"
#include "temporal/core/image.h"
#include "temporal/compare/comparison.h"
#include "temporal/pictures/html.h"
#include "temporal/pictures/picture.h"
#include "temporal/plot/plot.h"

#include "test_support.h"

#include <nlohmann/json.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <regex>
#include <set>
#include <sstream>

namespace temporal {
namespace {

namespace fs = std::filesystem;

std::string frame_name(const std::string& stem, int f) {
  char digits[16];
  std::snprintf(digits, sizeof digits, "%04d", f);
  return stem + "." + digits + ".exr";
}

// Six 64x48 frames at 40 fps: a reference with a bright edge moving right; `good` (noise 0.02, by filter-phlm),
// `noisy` (noise 0.1 and a smeared block, by filter-phlm), `input` (noise 0.2, written by render-gbuffer: its
// computeMs is a render's), `perceived` (morph-120hz --perceive output: a simulation's); a G-buffer with motion,
// depth, N and id.
void write_sequences(const fs::path& dir) {
  const int w = 64, h = 48;
  std::mt19937 rng(7);
  for (int f = 0; f < 6; ++f) {
    Image ref(w, h);
    for (const char* c : {"R", "G", "B"}) {
      float* p = ref.add_channel(c);
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
          p[std::size_t(y) * w + std::size_t(x)] =
              0.3f + 0.2f * std::sin(0.2f * float(x) + 0.1f * float(y)) + (x > 20 + 4 * f && x < 26 + 4 * f ? 0.6f : 0.0f);
    }
    ref.metadata().fps = 40.0;
    ref.metadata().tool = "render-gbuffer 0.1.0";
    ASSERT_TRUE(write_exr((dir / frame_name("ref", f)).string(), ref));
    auto test = [&](const char* stem, float amount, const char* tool, double ms, bool smear, bool perceived) {
      Image t(w, h);
      std::uniform_real_distribution<float> u(-amount, amount);
      for (const char* c : {"R", "G", "B"}) {
        float* p = t.add_channel(c);
        const float* r = ref.plane(c);
        for (int i = 0; i < w * h; ++i) p[i] = r[i] + u(rng);
        if (smear)
          for (int y = 30; y < 42; ++y)
            for (int x = 44; x < 58; ++x) p[std::size_t(y) * w + std::size_t(x)] = 0.9f;
      }
      t.metadata().fps = 40.0;
      t.metadata().tool = tool;
      t.metadata().compute_ms = ms;
      if (perceived) t.metadata().extra["perceivedWindow"] = "3";
      else if (std::string(tool).rfind("filter-phlm", 0) == 0) t.metadata().extra["method"] = stem;
      ASSERT_TRUE(write_exr((dir / frame_name(stem, f)).string(), t));
    };
    test("good", 0.02f, "filter-phlm 0.1.0", 5.0, false, false);
    test("noisy", 0.1f, "filter-phlm 0.1.0", 2.0, true, false);
    test("input", 0.2f, "render-gbuffer 0.1.0", 61.0, false, false);
    test("perceived", 0.05f, "morph-120hz 0.1.0", 40.0, false, true);
    Image g(w, h);
    g.add_channel("motion.X", 0.0f);
    g.add_channel("motion.Y", 0.0f);
    float* z = g.add_channel("depth.Z", 5.0f);
    for (int i = 0; i < w * h / 2; ++i) z[i] = 2.0f + float(i % w) * 0.01f;
    g.add_channel("N.X", 0.0f);
    g.add_channel("N.Y", 1.0f);
    g.add_channel("N.Z", 0.0f);
    std::uint32_t* id = g.add_uint_channel("id", 1);
    for (int i = 0; i < w * h / 3; ++i) id[i] = 2;
    g.metadata().far_clip = 100.0f;
    g.metadata().fps = 40.0;
    ASSERT_TRUE(write_exr((dir / frame_name("g", f)).string(), g));
  }
}

// Each test writes its own sequences into its own folder: CTest runs the tests of this file as parallel processes.
class Report : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = test::scratch_dir(std::string("report-") + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    write_sequences(dir);
  }
  ComparisonSetup setup(std::vector<std::string> tests, std::vector<std::string> names) const {
    ComparisonSetup s;
    s.reference = (dir / "ref.####.exr").string();
    for (const auto& t : tests) s.tests.push_back((dir / (t + ".####.exr")).string());
    s.names = std::move(names);
    s.gbuffer = (dir / "g.####.exr").string();
    return s;
  }
  int run(const std::string& args, std::string* out = nullptr) const {
    return test::run_command("cd " + dir.string() + " && env -u DISPLAY " + test::tool_path("compare").string() + " " + args,
                             out);
  }
  fs::path dir;
};

// --- The engine's frame observer -----------------------------------------------------------------------------

TEST_F(Report, EngineHandsEachFrameToTheObserverOnce) {
  ComparisonSetup s = setup({"good", "noisy"}, {"A", "B"});
  s.flip = FlipMode::Ldr;
  ComparisonHooks hooks;
  hooks.keep_maps = true;
  hooks.gbuffer_layers = {"N"};
  std::vector<int> frames;
  hooks.frame = [&](const ComparedFrame& cf) -> Status {
    frames.push_back(cf.frame);
    EXPECT_EQ(cf.count, 6u);
    EXPECT_TRUE(cf.reference && cf.reference->plane("R"));
    EXPECT_EQ(cf.reference->metadata().fps.value_or(0.0), 40.0);
    EXPECT_TRUE(cf.gbuffer && cf.gbuffer->plane("N.Y") && cf.gbuffer->plane("depth.Z") && cf.gbuffer->uint_plane("id"));
    EXPECT_NE(cf.gbuffer_path.find("g.000"), std::string::npos);
    EXPECT_EQ(cf.tests.size(), 2u);
    if (cf.tests.size() != 2) return {};
    EXPECT_EQ(cf.tests[0].name, "A");
    EXPECT_EQ(cf.tests[1].name, "B");
    for (const auto& t : cf.tests) {
      EXPECT_TRUE(t.image && t.image->plane("G"));
      EXPECT_TRUE(t.maps && t.maps->plane("error.flip") && t.maps->plane("error.Y") && t.maps->plane("error.invalid"));
      EXPECT_TRUE(t.metrics && t.metrics->frame == cf.frame && !std::isnan(t.metrics->value("flip")));
    }
    return {};
  };
  auto r = compare_sequences(s, hooks);
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_EQ(frames, (std::vector<int>{0, 1, 2, 3, 4, 5}));
  EXPECT_EQ(r->fps.value_or(0.0), 40.0);
  // An observer's error stops the run and comes back as the run's error.
  hooks.frame = [](const ComparedFrame& cf) -> Status {
    return cf.frame == 2 ? Status(Error::output("x.png", "disk full")) : Status::ok();
  };
  auto stopped = compare_sequences(s, hooks);
  ASSERT_FALSE(stopped);
  EXPECT_EQ(stopped.error().file, "x.png");
}

TEST(ComputeKind, FromTheHeadersToolAndAttributes) {
  FrameMetadata m;
  EXPECT_EQ(compute_kind_of(m), ComputeKind::Method);  // unknown producer: its time is taken as given
  m.tool = "filter-phlm 0.1.0";
  m.extra["method"] = "taa";
  EXPECT_EQ(compute_kind_of(m), ComputeKind::Method);
  m.tool = "render-gbuffer 0.1.0";
  EXPECT_EQ(compute_kind_of(m), ComputeKind::Render);
  m = {};
  m.tool = "morph-120hz 0.1.0";
  m.extra["perceivedWindow"] = "3";
  EXPECT_EQ(compute_kind_of(m), ComputeKind::Simulation);
  m.extra.erase("perceivedWindow");
  m.extra["method"] = "perceive";
  EXPECT_EQ(compute_kind_of(m), ComputeKind::Simulation);
  m.extra["method"] = "didyk";
  EXPECT_EQ(compute_kind_of(m), ComputeKind::Method);
  EXPECT_STREQ(compute_kind_name(ComputeKind::Render), "render");
}

// --- Plot defects (issue 13) -----------------------------------------------------------------------------------

// Titles are the metric's (after --title), never a file pattern; series are the --names; SSIM and FLIP axes stop
// at their largest possible value; the speed chart plots only the methods' own compute time: not the render time
// of a render-gbuffer input (filter-phlm's 61 ms "input") nor the simulation time of morph-120hz --perceive.
TEST_F(Report, ChartsHaveTitlesNamesRangesAndOnlyMethodTimes) {
  ComparisonSetup s = setup({"input", "good", "noisy", "perceived"}, {"input", "phlm", "taa", "perceived"});
  s.flip = FlipMode::Ldr;
  auto r = compare_sequences(s);
  ASSERT_TRUE(r) << r.error().message;
  const auto charts = comparison_charts(*r, "out/p.png", "walkers");
  std::set<std::string> files;
  for (const auto& [path, chart] : charts) {
    files.insert(fs::path(path).filename().string());
    EXPECT_EQ(chart.title.rfind("walkers: ", 0), 0u) << chart.title;
    EXPECT_EQ(chart.title.find(".exr"), std::string::npos) << chart.title;
    EXPECT_EQ(chart.title.find("####"), std::string::npos) << chart.title;
    EXPECT_EQ(chart.title.find("ref"), std::string::npos) << chart.title;
    EXPECT_NE(chart.y_label.find("("), std::string::npos) << "no unit on the y axis: " << chart.y_label;
    EXPECT_NE(chart.x_label.find("("), std::string::npos) << "no unit on the x axis: " << chart.x_label;
  }
  EXPECT_EQ(files, (std::set<std::string>{"p.png", "p-psnr-y.png", "p-ssim.png", "p-flicker.png", "p-flip.png", "p-speed.png"}));
  for (const auto& [path, chart] : charts) {
    const std::string f = fs::path(path).filename().string();
    const AxisRange y = chart_y_range(chart);
    if (f == "p-speed.png") {
      // input (render) and perceived (simulation) are left off; the two methods' 95 % intervals of the mean PSNR
      // are vertical error bars (issue 25); their compute times are constant, so there is no horizontal bar.
      ASSERT_EQ(chart.series.size(), 5u);
      for (std::size_t b : {3u, 4u}) {
        const ChartSeries& bar = chart.series[b];
        EXPECT_TRUE(bar.error_bar);
        EXPECT_EQ(bar.color, chart.series[b - 3].color);
        ASSERT_EQ(bar.x.size(), 2u);
        EXPECT_EQ(bar.x[0], chart.series[b - 3].x[0]);
        EXPECT_EQ(bar.x[1], chart.series[b - 3].x[0]);
        EXPECT_LT(bar.y[0], chart.series[b - 3].y[0]);
        EXPECT_GT(bar.y[1], chart.series[b - 3].y[0]);
      }
      EXPECT_EQ(chart.x_label.find("temporal:"), std::string::npos) << "an internal attribute name: " << chart.x_label;
      EXPECT_EQ(chart.series[2].name, "Pareto front");  // taa is faster, phlm better: both on it, by cost
      EXPECT_TRUE(chart.series[2].line);
      EXPECT_EQ(chart.series[2].x, (std::vector<double>{2.0, 5.0}));
      EXPECT_EQ(chart.series[0].name, "phlm");
      EXPECT_EQ(chart.series[1].name, "taa");
      EXPECT_DOUBLE_EQ(chart.series[0].x[0], 5.0);
      EXPECT_DOUBLE_EQ(chart.series[1].x[0], 2.0);
      EXPECT_EQ(chart.series[0].color, 1);  // phlm and taa keep their colours of the other charts
      EXPECT_EQ(chart.series[1].color, 2);
      EXPECT_NE(chart.x_label.find("ms"), std::string::npos);
      continue;
    }
    ASSERT_EQ(chart.series.size(), 4u) << f;
    EXPECT_EQ(chart.series[1].name, "phlm");
    EXPECT_EQ(chart.series[3].name, "perceived");
    EXPECT_EQ(chart.series[1].color, 1);
    if (f == "p-ssim.png") {
      EXPECT_LE(y.high, 1.0) << "the SSIM axis runs past 1";
      EXPECT_DOUBLE_EQ(y.high, 1.0);  // the best SSIM (~0.999) plus the margin reaches the cap
    }
    if (f == "p-flip.png") {
      EXPECT_GE(y.low, 0.0);
      EXPECT_LE(y.high, 1.0);
    }
    if (f == "p-flicker.png") {
      EXPECT_GE(y.low, 0.0);
    }
  }
  // Without --title: the metric's title alone.
  for (const auto& [path, chart] : comparison_charts(*r, "p.png")) EXPECT_EQ(chart.title.find(": "), std::string::npos) << chart.title;
  // The JSON says what each compute time is.
  const auto json_path = test::scratch_dir("report-json") / "m.json";
  ASSERT_TRUE(write_comparison_json(*r, {}, {}, "compare", "", json_path.string()));
  const auto j = nlohmann::json::parse(test::read_file(json_path));
  EXPECT_EQ(j["sequences"][1]["compute_kind"], "method");
  EXPECT_EQ(j["sequences"][0]["compute_kind"], "render");
  EXPECT_EQ(j["sequences"][3]["compute_kind"], "simulation");
  EXPECT_EQ(j["sequences"][0]["tool"], "render-gbuffer 0.1.0");
}

// Hand-made points (cost, score): a dominated point, a tie in cost, a tie in both, non-finite values.
TEST(ParetoFront, HandValues) {
  //                  0    1    2    3    4    5    6
  const std::vector<double> cost{5.0, 2.0, 3.0, 2.0, 9.0, NAN, 1.0};
  const std::vector<double> score{30.0, 25.0, 24.0, 26.0, 30.0, 40.0, -INFINITY};
  // 2 is dominated by 3 (cheaper, better); 1 by 3 (same cost, better); 4 by 0 (same score, cheaper); 5 and 6
  // are not finite. The front by cost: 3 (2 ms, 26), 0 (5 ms, 30).
  EXPECT_EQ(pareto_front(cost, score), (std::vector<std::size_t>{3, 0}));
  // Equal points do not dominate each other.
  EXPECT_EQ(pareto_front({1.0, 1.0}, {2.0, 2.0}), (std::vector<std::size_t>{0, 1}));
  EXPECT_TRUE(pareto_front({}, {}).empty());
}

TEST(ChartRange, HandValues) {
  Chart c;
  c.series.push_back({"a", {0, 1, 2}, {0.90, 0.95, 0.99}});
  AxisRange r = chart_y_range(c);  // span 0.09: 5 % margins
  EXPECT_NEAR(r.low, 0.8955, 1e-12);
  EXPECT_NEAR(r.high, 0.9945, 1e-12);
  c.y_highest = 1.0;  // SSIM: nothing changes below the cap
  EXPECT_NEAR(chart_y_range(c).high, 0.9945, 1e-12);
  c.series[0].y = {0.99, 1.0, 1.0};
  EXPECT_DOUBLE_EQ(chart_y_range(c).high, 1.0);  // 1.0005 capped
  c.series[0].y = {1.0, 1.0, 1.0};               // flat at the cap: 1 +- 10 %, capped above
  r = chart_y_range(c);
  EXPECT_NEAR(r.low, 0.995, 1e-12);
  EXPECT_DOUBLE_EQ(r.high, 1.0);
  c.y_min = 0.5;  // given ends win
  c.y_max = 1.2;
  r = chart_y_range(c);
  EXPECT_DOUBLE_EQ(r.low, 0.5);
  EXPECT_DOUBLE_EQ(r.high, 1.2);
  Chart empty;
  empty.series.push_back({"nan", {0}, {std::nan("")}});
  EXPECT_DOUBLE_EQ(chart_y_range(empty).high - chart_y_range(empty).low, 1.1);
}

TEST(ChartFormat, ByExtensionAndNothingElse) {
  EXPECT_EQ(*chart_format("a/b.png"), ChartFormat::Png);
  EXPECT_EQ(*chart_format("b.SVG"), ChartFormat::Svg);
  EXPECT_EQ(*chart_format("fig.pdf"), ChartFormat::Pdf);
  for (const char* bad : {"fig.jpg", "fig", "fig.eps", "fig.pdf.txt"}) {
    auto f = chart_format(bad);
    ASSERT_FALSE(f) << bad;
    EXPECT_EQ(f.error().kind, ErrorKind::Usage);
    EXPECT_NE(f.error().message.find(".png, .svg or .pdf"), std::string::npos);
  }
}

// `compare --plot fig.pdf` wrote PNG bytes into the .pdf and exited 0: each extension now gets its format, and any
// other extension is a usage error before anything runs.
TEST_F(Report, PlotWritesPngSvgOrPdfByExtensionAndRefusesOthers) {
  if (test::run_command("command -v Xvfb >/dev/null") != 0) GTEST_SKIP() << "Xvfb is not installed";
  std::string out;
  const std::string base = "--reference ref.####.exr good.####.exr noisy.####.exr --names phlm,taa --title walkers ";
  ASSERT_EQ(run(base + "--plot charts/fig.pdf", &out), 0) << out;
  ASSERT_EQ(run(base + "--plot charts/fig.svg", &out), 0) << out;
  ASSERT_EQ(run(base + "--plot charts/fig.png", &out), 0) << out;
  const fs::path d = dir / "charts";
  for (const char* stem : {"fig", "fig-psnr-y", "fig-ssim", "fig-flicker", "fig-speed"}) {
    const std::string pdf = test::read_file(d / (std::string(stem) + ".pdf"));
    EXPECT_EQ(pdf.rfind("%PDF-", 0), 0u) << stem << ".pdf is not a PDF";
    const std::string svg = test::read_file(d / (std::string(stem) + ".svg"));
    EXPECT_NE(svg.find("<svg"), std::string::npos) << stem << ".svg is not an SVG";
    EXPECT_NE(svg.find(">walkers: "), std::string::npos) << stem << ".svg has no title text";
    EXPECT_NE(svg.find(">phlm"), std::string::npos) << stem << ".svg has no legend text";
    const std::string png = test::read_file(d / (std::string(stem) + ".png"));
    EXPECT_EQ(png.compare(0, 8, std::string("\x89PNG\r\n\x1a\n", 8)), 0) << stem << ".png is not a PNG";
  }
  // The SSIM chart's tick labels stop at 1 (the old chart ran to 1.15).
  const std::string ssim = test::read_file(d / "fig-ssim.svg");
  for (const char* tick : {">1.05<", ">1.1<", ">1.15<"}) EXPECT_EQ(ssim.find(tick), std::string::npos) << tick;
  for (const std::string bad : {"--plot fig.jpg", "--plot fig", "--plot fig.eps"}) {
    EXPECT_EQ(run(base + bad + " --csv never.csv", &out), 1) << bad << "\n" << out;
    EXPECT_NE(out.find(".png, .svg or .pdf"), std::string::npos) << out;
    EXPECT_FALSE(fs::exists(dir / "never.csv")) << "the run went ahead after a refused --plot";
  }
  for (const auto& e : fs::directory_iterator(d)) EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos);
}

// A binary PPM (P6, as pdftoppm writes by default): width, height and RGB bytes; empty when unreadable.
struct Ppm {
  int width = 0, height = 0;
  std::string rgb;
};
Ppm read_ppm(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::string magic;
  int maxval = 0;
  Ppm p;
  if (!(in >> magic >> p.width >> p.height >> maxval) || magic != "P6" || maxval != 255) return {};
  in.get();  // the one whitespace byte before the pixels
  p.rgb.resize(std::size_t(p.width) * std::size_t(p.height) * 3);
  if (!in.read(p.rgb.data(), std::streamsize(p.rgb.size()))) return {};
  return p;
}

// Issue 25: VTK's libharu PDF drew every data marker as a disc filling the plot area and left Helvetica unembedded;
// the test only checked that a file was written. Now each PDF chart is rendered to pixels by poppler (as a reader
// would see it): the first series' colour (Okabe-Ito blue 0,114,178) covers some pixels (its markers and line are
// drawn) but less than a quarter of the page (a disc filling the plot area covers more than half of it), the
// page is mostly white, and pdffonts lists at least one font, every one embedded.
TEST_F(Report, PdfChartsDrawMarkersAtTheirSizeAndEmbedTheirFonts) {
  if (test::run_command("command -v Xvfb >/dev/null") != 0) GTEST_SKIP() << "Xvfb is not installed";
  ASSERT_EQ(test::run_command("command -v pdftoppm >/dev/null && command -v pdffonts >/dev/null"), 0)
      << "pdftoppm and pdffonts (Debian's poppler-utils, installed by ./setup.sh) are needed to check the PDF charts";
  std::string out;
  ASSERT_EQ(run("--reference ref.####.exr good.####.exr noisy.####.exr --names phlm,taa --title walkers "
                "--plot charts/fig.pdf",
                &out),
            0)
      << out;
  const fs::path d = dir / "charts";
  for (const char* stem : {"fig", "fig-psnr-y", "fig-ssim", "fig-flicker", "fig-speed"}) {
    const fs::path pdf = d / (std::string(stem) + ".pdf");
    const fs::path ppm = d / (std::string(stem) + ".ppm");
    ASSERT_EQ(test::run_command("pdftoppm -r 96 -singlefile '" + pdf.string() + "' '" + (d / stem).string() + "'", &out),
              0)
        << out;
    const Ppm page = read_ppm(ppm);
    ASSERT_GT(page.width, 100) << stem << ": pdftoppm wrote no readable page";
    const std::size_t n = std::size_t(page.width) * std::size_t(page.height);
    std::size_t blue = 0, inked = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const int r = static_cast<unsigned char>(page.rgb[3 * i]), g = static_cast<unsigned char>(page.rgb[3 * i + 1]),
                b = static_cast<unsigned char>(page.rgb[3 * i + 2]);
      if (std::abs(r - 0) + std::abs(g - 114) + std::abs(b - 178) < 60) ++blue;
      if (r < 235 || g < 235 || b < 235) ++inked;
    }
    EXPECT_GT(blue, 20u) << stem << ": the first series is not drawn";
    EXPECT_LT(double(blue), 0.25 * double(n)) << stem << ": the first series' markers cover " << blue << " of " << n
                                              << " pixels";
    EXPECT_LT(double(inked), 0.4 * double(n)) << stem << ": " << inked << " of " << n << " pixels are not white";
    ASSERT_EQ(test::run_command("pdffonts '" + pdf.string() + "'", &out), 0) << out;
    // pdffonts: two header lines, then one line per font: name type encoding emb sub uni object ID.
    std::istringstream lines(out);
    std::string line;
    int fonts = 0;
    for (int i = 0; std::getline(lines, line); ++i) {
      if (i < 2 || line.empty()) continue;
      ++fonts;
      const std::regex embedded(R"( (yes|no) +(yes|no) +(yes|no) +\d+ +\d+ *$)");
      std::smatch m;
      ASSERT_TRUE(std::regex_search(line, m, embedded)) << stem << ": cannot read pdffonts' line '" << line << "'";
      EXPECT_EQ(m[1].str(), "yes") << stem << ": a font is not embedded: " << line;
    }
    EXPECT_GT(fonts, 0) << stem << ": no font (the title and labels should be text)\n" << out;
  }
}

// Issue 25: `compare --report DIR` into a folder holding an earlier run's report left that run's pictures beside the
// new ones. The earlier report's files (and only those: a file of the user's own stays) are removed first; a
// folder holding report-like files without a report of compare is refused, saying what to do.
TEST_F(Report, ReportReplacesAnEarlierReportAndRefusesForeignFiles) {
  if (test::run_command("command -v Xvfb >/dev/null") != 0) GTEST_SKIP() << "Xvfb is not installed";
  std::string out;
  const std::string base = "--reference ref.####.exr ";
  run(base + "good.####.exr noisy.####.exr --names phlm,taa --report rep", &out);  // exit 4 without ffmpeg
  ASSERT_TRUE(fs::exists(dir / "rep/index.html")) << out;
  ASSERT_TRUE(fs::exists(dir / "rep/pictures/taa-error.png")) << out;
  std::ofstream(dir / "rep/notes.txt") << "mine";             // the user's own file
  std::ofstream(dir / "rep/pictures/stale.png") << "old";     // a picture of a run before
  run(base + "good.####.exr --names phlm --report rep --verbose", &out);
  ASSERT_TRUE(fs::exists(dir / "rep/index.html")) << out;
  EXPECT_FALSE(fs::exists(dir / "rep/pictures/taa-error.png")) << "the earlier run's taa picture stayed";
  EXPECT_FALSE(fs::exists(dir / "rep/pictures/stale.png"));
  EXPECT_TRUE(fs::exists(dir / "rep/pictures/phlm-error.png")) << out;
  EXPECT_TRUE(fs::exists(dir / "rep/notes.txt")) << "a file the report does not own was removed";
  EXPECT_NE(out.find("removed the earlier report in rep"), std::string::npos) << out;
  EXPECT_EQ(test::read_file(dir / "rep/index.html").find(">taa<"), std::string::npos) << "the new page shows taa";
  // Report folders without a report of compare: refused before anything is measured or removed.
  fs::create_directories(dir / "other/pictures");
  std::ofstream(dir / "other/pictures/keep.png") << "someone's";
  EXPECT_EQ(run(base + "good.####.exr --report other --csv other.csv", &out), 1) << out;
  EXPECT_NE(out.find("holds pictures but no earlier report of compare"), std::string::npos) << out;
  EXPECT_NE(out.find("give --report a new or empty folder"), std::string::npos) << out;
  EXPECT_TRUE(fs::exists(dir / "other/pictures/keep.png"));
  EXPECT_FALSE(fs::exists(dir / "other.csv"));
}

// --- Progress line -----------------------------------------------------------------------------------------------

// On a terminal (a pseudo-terminal made by `script`) the progress line is erased before the table: the bytes right
// before the table's header are the erase sequence, not progress text.
TEST_F(Report, ProgressLineIsErasedBeforeTheTable) {
  if (test::run_command("command -v script >/dev/null") != 0) GTEST_SKIP() << "script (util-linux) is not installed";
  std::string out;
  ASSERT_EQ(test::run_command("cd " + dir.string() + " && script -qec '" + test::tool_path("compare").string() +
                                  " --reference ref.####.exr good.####.exr noisy.####.exr' /dev/null",
                              &out),
            0)
      << out;
  const auto at = out.find("sequence");
  ASSERT_NE(at, std::string::npos) << out;
  ASSERT_GE(at, 4u);
  EXPECT_EQ(out.substr(at - 4, 4), "\r\033[K") << "the table is glued to: " << out.substr(0, at);
  EXPECT_NE(out.find("compare: frame 0 (1/6"), std::string::npos) << "no progress line drawn: " << out;
  EXPECT_EQ(out.find("e+"), std::string::npos) << out;  // no rate in exponent notation
}

// --- compare --png and --report --------------------------------------------------------------------------------

TEST_F(Report, PngWritesEveryFrameAndTheSheet) {
  std::string out;
  ASSERT_EQ(run("--reference ref.####.exr good.####.exr noisy.####.exr --names phlm,taa --gbuffer g.####.exr "
                "--flip ldr --png png --frames 1-3 --sheet-frame 2 --crop 40,25,16,16 --profile column:30",
                &out),
            0)
      << out;
  const fs::path d = dir / "png";
  for (int f = 1; f <= 3; ++f) {
    char n[8];
    std::snprintf(n, sizeof n, "%04d", f);
    for (const std::string stem : {"reference", "phlm", "taa", "phlm-flip", "taa-error", "gbuffer-depth", "gbuffer-normal",
                                   "gbuffer-motion", "gbuffer-id"}) {
      auto p = read_picture((d / (stem + "." + n + ".png")).string());
      ASSERT_TRUE(p) << stem << " " << n;
      if (stem.find("-") == std::string::npos) {
        EXPECT_EQ(p->width(), 64) << stem;
        EXPECT_EQ(p->height(), 48) << stem;
      } else if (stem.rfind("gbuffer", 0) == 0) {
        EXPECT_EQ(p->width(), 64) << stem;
        EXPECT_EQ(p->height(), 48) << stem;
      } else if (stem.rfind("gbuffer", 0) != 0) {
        EXPECT_GE(p->width(), 64) << stem;  // the colour bar under it is at least 120 pixels wide
        EXPECT_GT(p->height(), 48) << stem << ": no colour bar";
      }
    }
  }
  EXPECT_TRUE(fs::exists(d / "sheet.0002.png"));
  EXPECT_FALSE(fs::exists(d / "sheet.0003.png"));
  EXPECT_TRUE(fs::exists(d / "profile-column-30.png"));
  EXPECT_FALSE(fs::exists(d / "reference.0004.png"));
  // A frame outside the compared ones, a crop outside the image, a bad format: usage errors.
  EXPECT_EQ(run("--reference ref.####.exr good.####.exr --png png2 --sheet-frame 9", &out), 1) << out;
  EXPECT_EQ(run("--reference ref.####.exr good.####.exr --png png2 --crop 60,40,10,10", &out), 1) << out;
  EXPECT_EQ(run("--reference ref.####.exr good.####.exr --png png2 --png-format gif", &out), 1) << out;
  EXPECT_EQ(run("--reference ref.####.exr good.####.exr --png png2 --display nothing", &out), 1) << out;
}

// No output of the pictures replaces an input: a test sequence that lives where the report writes its maps.
TEST_F(Report, ReportRefusesToReplaceAnInput) {
  fs::create_directories(dir / "clash" / "maps");
  for (int f = 0; f < 6; ++f) fs::copy_file(dir / frame_name("good", f), dir / "clash" / "maps" / frame_name("phlm", f),
                                            fs::copy_options::overwrite_existing);
  const std::string before = test::read_file(dir / "clash" / "maps" / "phlm.0005.exr");
  std::string out;
  EXPECT_EQ(run("--reference ref.####.exr clash/maps/phlm.####.exr --names phlm --report clash", &out), 1) << out;
  EXPECT_NE(out.find("one of this run's inputs"), std::string::npos) << out;
  EXPECT_EQ(test::read_file(dir / "clash" / "maps" / "phlm.0005.exr"), before);
}

// Every file the page names exists; links point to EXRs; nothing comes from a network; the tables hold the JSON's
// intervals.
TEST_F(Report, ReportPageIsCompleteAndOffline) {
  std::string out;
  ASSERT_EQ(run("--reference ref.####.exr good.####.exr noisy.####.exr input.####.exr --names phlm,taa,input "
                "--gbuffer g.####.exr --flip ldr --title 'test scene' --report rep",
                &out),
            0)
      << out;
  const fs::path d = dir / "rep";
  const std::string html = test::read_file(d / "index.html");
  ASSERT_FALSE(html.empty());
  EXPECT_EQ(html.find("http://"), std::string::npos);
  EXPECT_EQ(html.find("https://"), std::string::npos);
  EXPECT_EQ(html.find("//cdn"), std::string::npos);
  // Every src and href names a file that exists (relative to the page).
  std::regex attr(R"re((src|href|poster)="([^"#]+)")re");
  std::size_t exr_links = 0, images = 0;
  for (auto it = std::sregex_iterator(html.begin(), html.end(), attr); it != std::sregex_iterator(); ++it) {
    const std::string target = (*it)[2].str();
    EXPECT_TRUE(fs::exists(d / target)) << target;
    exr_links += target.size() > 4 && target.compare(target.size() - 4, 4, ".exr") == 0;
    images += (*it)[1].str() == "src";
  }
  EXPECT_GE(exr_links, 3u * 3u);  // sheet tiles, maps, profiles, G-buffer
  EXPECT_GE(images, 10u);
  for (const char* part : {"<table class=\"metrics\">", "<table class=\"paired\">", "id=\"plots\"", "id=\"sheet\"",
                           "id=\"flip\"", "id=\"error\"", "id=\"profiles\"", "id=\"gbuffer\"", "<video", "class=\"mapped\"",
                           "test scene", "input: left off the speed chart"})
    EXPECT_NE(html.find(part), std::string::npos) << part;
  // Each <img> inside a link or with an image map: every picture leads to its data.
  std::regex img(R"(<img [^>]*>)");
  for (auto it = std::sregex_iterator(html.begin(), html.end(), img); it != std::sregex_iterator(); ++it) {
    const std::string tag = it->str();
    const auto pos = std::size_t(it->position());
    const std::string before = html.substr(pos >= 60 ? pos - 60 : 0, pos >= 60 ? 60 : pos);
    const bool mapped = before.find("<div class=\"mapped\"") != std::string::npos;  // links over its parts
    const auto open = before.rfind("<a href="), close = before.rfind("</a>");
    const bool linked = open != std::string::npos && (close == std::string::npos || close < open);
    EXPECT_TRUE(mapped || linked) << tag;
  }
  // The table's intervals are the JSON's ci95 (same bootstrap), formatted to four significant digits.
  const auto j = nlohmann::json::parse(test::read_file(d / "metrics.json"));
  for (const auto& s : j["sequences"]) {
    const auto& ci = s["ssim"]["ci95"];
    const std::string cell = "[" + format_number(ci[0].get<double>(), 4) + ", " + format_number(ci[1].get<double>(), 4) + "]";
    EXPECT_NE(html.find(cell), std::string::npos) << s["name"] << " " << cell;
  }
  // The files themselves.
  auto sheet = read_picture((d / "pictures" / "sheet.png").string());
  ASSERT_TRUE(sheet);
  EXPECT_GT(sheet->width(), 4 * 64);   // reference + three methods
  EXPECT_GT(sheet->height(), 3 * 48);  // images, FLIP maps, crops
  auto maps = read_exr((d / "maps" / "phlm.0005.exr").string());  // the last frame
  ASSERT_TRUE(maps) << maps.error().message;
  EXPECT_NE(maps->plane("error.flip"), nullptr);
  auto profile = read_exr((d / "profiles" / "reference-row-24.exr").string());
  ASSERT_TRUE(profile) << profile.error().message;
  EXPECT_EQ(profile->width(), 64);
  EXPECT_EQ(profile->height(), 6);
  std::string probe;
  ASSERT_EQ(test::run_command("ffprobe -v error -select_streams v:0 -show_entries stream=codec_name,r_frame_rate -of "
                              "default=nw=1 " + (d / "video.mp4").string(), &probe), 0) << probe;
  EXPECT_NE(probe.find("codec_name=h264"), std::string::npos) << probe;
  EXPECT_NE(probe.find("r_frame_rate=40/1"), std::string::npos) << probe;
  for (const auto& e : fs::recursive_directory_iterator(d))
    EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << e.path();
}

// Issue 24: with --regions motion the report has a Regions section - one stacked share bar per sequence, the
// per-region table whose intervals are the JSON's - and the paired differences per region and pooled.
TEST_F(Report, RegionsSectionWithShareBarsAndTable) {
  std::string out;
  ASSERT_EQ(run("--reference ref.####.exr good.####.exr noisy.####.exr --names phlm,taa --gbuffer g.####.exr "
                "--regions motion --static-frames 2 --report rep",
                &out),
            0)
      << out;
  const std::string html = test::read_file(dir / "rep" / "index.html");
  for (const char* part : {"<h2 id=\"regions\">Regions</h2>", "<table class=\"regions\">", "<div class=\"share\">",
                           "<span class=\"static\"", "<span class=\"moving\"", "<span class=\"disoccluded\"",
                           "<th class=\"name\">region</th>", "psnr_rgb_pooled"})
    EXPECT_NE(html.find(part), std::string::npos) << part;
  std::size_t bars = 0;
  for (auto at = html.find("<div class=\"share\">"); at != std::string::npos; at = html.find("<div class=\"share\">", at + 1))
    ++bars;
  EXPECT_EQ(bars, 2u);
  const auto j = nlohmann::json::parse(test::read_file(dir / "rep" / "metrics.json"));
  for (const auto& s : j["sequences"]) {
    const auto& ci = s["regions"]["disoccluded"]["psnr_rgb"]["ci95"];
    const std::string cell = "[" + format_number(ci[0].get<double>(), 4) + ", " + format_number(ci[1].get<double>(), 4) + "]";
    EXPECT_NE(html.find(cell), std::string::npos) << s["name"] << " " << cell;
  }
}

// The charts of --regions: the shares per frame (summing to 100 %) and PSNR per frame in each region.
TEST_F(Report, RegionChartsFromTheReport) {
  ComparisonSetup s = setup({"good", "noisy"}, {"phlm", "taa"});
  s.regions = true;
  s.region_options.static_frames = 2;
  auto report = compare_sequences(s);
  ASSERT_TRUE(report) << report.error().message;
  const auto charts = comparison_charts(*report, (dir / "c.png").string(), "scene");
  std::map<std::string, const Chart*> by;
  for (const auto& [path, chart] : charts) by[fs::path(path).filename().string()] = &chart;
  ASSERT_TRUE(by.count("c-regions.png"));
  const Chart& shares = *by["c-regions.png"];
  ASSERT_EQ(shares.series.size(), 3u);
  EXPECT_EQ(shares.series[0].name, "static");
  for (std::size_t k = 0; k < shares.series[0].y.size(); ++k)
    EXPECT_NEAR(shares.series[0].y[k] + shares.series[1].y[k] + shares.series[2].y[k], 100.0, 1e-9) << k;
  EXPECT_EQ(shares.series[2].y.front(), 100.0);  // the first frame has no history: all disoccluded
  for (const char* region : {"static", "moving", "disoccluded"}) {
    const std::string name = std::string("c-psnr-") + region + ".png";
    ASSERT_TRUE(by.count(name)) << name;
    EXPECT_EQ(by[name]->series.size(), 2u);
    EXPECT_NE(by[name]->title.find(region), std::string::npos);
  }
  // Without regions, none of them.
  s.regions = false;
  auto plain = compare_sequences(s);
  ASSERT_TRUE(plain);
  for (const auto& [path, chart] : comparison_charts(*plain, (dir / "c.png").string()))
    EXPECT_EQ(fs::path(path).filename().string().find("region"), std::string::npos) << path;
}

// The report in a browser: headless Chromium loads the page from disk, renders it to a PNG and dumps its DOM.
// The screenshot is not blank (many colours, much non-white: tables, charts, pictures), every <img> finished
// loading (the page's own script counts them into data-images-complete), and the page has its tables, charts,
// contact sheet with crops, FLIP maps and a video element.
TEST_F(Report, ChromiumRendersTheReport) {
  std::string chromium;
  for (const char* c : {"chromium", "chromium-browser"})
    if (test::run_command(std::string("command -v ") + c + " >/dev/null") == 0) chromium = c;
  if (chromium.empty()) GTEST_SKIP() << "chromium is not installed (setup.sh installs it)";
  std::string out;
  ASSERT_EQ(run("--reference ref.####.exr good.####.exr noisy.####.exr --names phlm,taa --gbuffer g.####.exr "
                "--flip ldr --title 'browser check' --report browser",
                &out),
            0)
      << out;
  const fs::path page = fs::canonical(dir / "browser" / "index.html");
  const fs::path shot = dir / "browser-screenshot.png";
  const fs::path profile = test::scratch_dir("report-chromium-profile");
  // As root Chromium needs --no-sandbox; --disable-gpu and an empty profile keep it headless and quiet here.
  const std::string flags = " --headless --no-sandbox --disable-gpu --disable-dev-shm-usage --hide-scrollbars "
                            "--no-first-run --mute-audio --user-data-dir=" + profile.string() +
                            " --virtual-time-budget=10000 --window-size=1280,2400 ";
  ASSERT_EQ(test::run_command("timeout 120 " + chromium + flags + "--screenshot=" + shot.string() + " file://" +
                                  page.string() + " 2>&1",
                              &out),
            0)
      << out;
  auto pic = read_picture(shot.string());
  ASSERT_TRUE(pic) << out;
  EXPECT_EQ(pic->width(), 1280);
  std::set<std::uint32_t> colours;
  std::size_t non_white = 0;
  for (int y = 0; y < pic->height(); ++y)
    for (int x = 0; x < pic->width(); ++x) {
      const Rgb8 c = pic->at(x, y);
      colours.insert(std::uint32_t(c.r) << 16 | std::uint32_t(c.g) << 8 | c.b);
      non_white += c.r < 240 || c.g < 240 || c.b < 240;
    }
  EXPECT_GT(colours.size(), 500u) << "the screenshot is nearly uniform";
  EXPECT_GT(non_white, std::size_t(pic->width()) * std::size_t(pic->height()) / 20) << "the screenshot is mostly blank";
  std::string dom;
  ASSERT_EQ(test::run_command("timeout 120 " + chromium + flags + "--dump-dom file://" + page.string() + " 2>/dev/null", &dom), 0);
  std::smatch m;
  ASSERT_TRUE(std::regex_search(dom, m, std::regex(R"re(data-images-complete="(\d+)/(\d+)")re"))) << dom.substr(0, 2000);
  EXPECT_EQ(m[1].str(), m[2].str()) << "pictures that did not load";
  EXPECT_GE(std::stoi(m[2].str()), 10);
  for (const char* part : {"<table class=\"metrics\">", "class=\"chart\"", "class=\"sheet\"", "crop 1", "class=\"flip\"",
                           "<video", "class=\"profile\""})
    EXPECT_NE(dom.find(part), std::string::npos) << part;
  std::printf("screenshot: %s (%dx%d, %zu colours); images %s/%s\n", shot.c_str(), pic->width(), pic->height(),
              colours.size(), m[1].str().c_str(), m[2].str().c_str());
}

}  // namespace
}  // namespace temporal
