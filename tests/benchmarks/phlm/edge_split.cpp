// phlm_edge_split: where the error of filtered sequences lies, edges against surface interiors, and whether an
// output is shifted against its reference. The measurement behind docs/filter-phlm.md "Edges under camera motion"
// (issue 16, item 8); run by pipelines/filter-phlm-edges.sh.
//
//   phlm_edge_split --reference R.####.exr --gbuffer G.####.exr [--frames A-B] [--warmup N]
//                   NAME=TEST.####.exr [NAME=TEST.####.exr ...]
//
// Edge pixels: pixels whose 3x3 neighbourhood in the G-buffer holds another surface by the suite's one rule
// (temporal/core/reproject.h same_surface: another material id, or a linear depth more than 5 % away). Per frame and
// test: the mean squared error of R, G, B against the reference on edge pixels and on the others; PSNR (peak 1).
// Shift: per axis, the translation in [-0.6, 0.6] (steps of 0.05 px) that minimises the squared luminance error of
// the bilinearly shifted output against the reference over the image less a 2-pixel margin, summed over the frames
// after the warm-up. A blurred output has its minimum at 0; a half-pixel convention mismatch at +-0.5.
// The first test is the baseline of the relative columns (give the unfiltered input first).
// Prints a Markdown table; exit 1 on bad usage, 2 on unreadable input.
#include "temporal/core/exr.h"
#include "temporal/core/reproject.h"
#include "temporal/core/sequence.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace {

using namespace temporal;

struct Test {
  std::string name;
  SequencePattern pattern;
  double sse_edge = 0.0, sse_inner = 0.0;  // summed over frames (after the warm-up)
  double psnr_sum = 0.0;
  int frames = 0;
  std::vector<double> shift_x, shift_y;  // squared error per candidate shift
};

constexpr int kShifts = 25;  // -0.6 .. 0.6 in steps of 0.05
double shift_of(int k) { return -0.6 + 0.05 * k; }

double luma(const Image& img, std::size_t i) {
  return 0.2126 * img.plane("R")[i] + 0.7152 * img.plane("G")[i] + 0.0722 * img.plane("B")[i];
}

int fail(const std::string& text, int code) {
  std::fprintf(stderr, "phlm_edge_split: %s\n", text.c_str());
  return code;
}

// Sample of plane p (w x h) at (x + dx, y + dy), bilinear, pixel centres at integers.
float bilinear_at(const float* p, int w, int h, double fx, double fy) {
  const reproject::Bilinear b = reproject::bilinear(float(fx), float(fy), w, h);
  return b(p);
}

}  // namespace

int main(int argc, char** argv) {
  std::string reference, gbuffer, frames_text;
  int warmup = 0;
  std::vector<Test> tests;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string { return i + 1 < argc ? argv[++i] : std::string(); };
    if (a == "--reference") {
      reference = value();
    } else if (a == "--gbuffer") {
      gbuffer = value();
    } else if (a == "--frames") {
      frames_text = value();
    } else if (a == "--warmup") {
      warmup = std::atoi(value().c_str());
    } else if (a.find('=') != std::string::npos && a[0] != '-') {
      auto pattern = SequencePattern::parse(a.substr(a.find('=') + 1));
      if (!pattern) return fail(pattern.error().message, 1);
      tests.push_back({a.substr(0, a.find('=')), *pattern, 0, 0, 0, 0, std::vector<double>(kShifts, 0.0),
                       std::vector<double>(kShifts, 0.0)});
    } else {
      return fail("unknown argument '" + a + "'; usage: --reference R --gbuffer G [--frames A-B] [--warmup N] NAME=TEST ...", 1);
    }
  }
  if (reference.empty() || gbuffer.empty() || tests.empty())
    return fail("needs --reference, --gbuffer and at least one NAME=TEST.####.exr", 1);
  auto ref_pattern = SequencePattern::parse(reference);
  auto g_pattern = SequencePattern::parse(gbuffer);
  if (!ref_pattern || !g_pattern) return fail("bad --reference or --gbuffer pattern", 1);
  std::optional<FrameRange> range;
  if (!frames_text.empty()) {
    auto r = FrameRange::parse(frames_text);
    if (!r) return fail(r.error().message, 1);
    range = *r;
  }
  auto frames = resolve_frames(*ref_pattern, range);
  if (!frames) return fail(frames.error().message, 2);

  double edge_fraction = 0.0;
  int counted = 0;
  const reproject::SurfaceTest rule{};
  for (std::size_t f = 0; f < frames->size(); ++f) {
    const int frame = (*frames)[f];
    auto ref = read_exr(ref_pattern->path(frame), {{"rgb"}});
    if (!ref) return fail(ref.error().message, 2);
    auto g = read_exr(g_pattern->path(frame), {{"depth", "id"}});
    if (!g) return fail(g.error().message, 2);
    const int w = ref->width(), h = ref->height();
    const float* z = g->plane("depth.Z");
    const std::uint32_t* id = g->uint_plane("id");
    if (!z || !id) return fail(g_pattern->path(frame) + ": needs depth.Z and id", 2);
    std::vector<std::uint8_t> edge(std::size_t(w) * std::size_t(h), 0);
    std::size_t edges = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const std::size_t i = std::size_t(y) * std::size_t(w) + std::size_t(x);
        bool e = false;
        for (int j = std::max(y - 1, 0); j <= std::min(y + 1, h - 1); ++j)
          for (int k = std::max(x - 1, 0); k <= std::min(x + 1, w - 1); ++k) {
            const std::size_t n = std::size_t(j) * std::size_t(w) + std::size_t(k);
            e = e || !reproject::same_surface(z[i], id[i], z[n], id[n], rule);
          }
        edge[i] = e ? 1 : 0;
        edges += e ? 1 : 0;
      }
    const bool steady = int(f) >= warmup;
    if (steady) {
      edge_fraction += double(edges) / double(edge.size());
      ++counted;
    }
    const char* names[3] = {"R", "G", "B"};
    for (auto& t : tests) {
      auto img = read_exr(t.pattern.path(frame), {{"rgb"}});
      if (!img) return fail(img.error().message, 2);
      if (img->width() != w || img->height() != h) return fail(t.pattern.path(frame) + ": size differs from the reference", 2);
      if (!steady) continue;
      double se = 0.0, si = 0.0;
      for (int c = 0; c < 3; ++c) {
        const float* a = img->plane(names[c]);
        const float* b = ref->plane(names[c]);
        for (std::size_t i = 0; i < edge.size(); ++i) {
          const double d = double(a[i]) - double(b[i]);
          (edge[i] ? se : si) += d * d;
        }
      }
      std::vector<float> ly(edge.size()), lr(edge.size());
      for (std::size_t i = 0; i < edge.size(); ++i) {
        ly[i] = float(luma(*img, i));
        lr[i] = float(luma(*ref, i));
      }
      for (int k = 0; k < kShifts; ++k) {
        double sx = 0.0, sy = 0.0;
        for (int y = 2; y < h - 2; ++y)
          for (int x = 2; x < w - 2; ++x) {
            const double r = lr[std::size_t(y) * std::size_t(w) + std::size_t(x)];
            const double dx = double(bilinear_at(ly.data(), w, h, x + shift_of(k), y)) - r;
            const double dy = double(bilinear_at(ly.data(), w, h, x, y + shift_of(k))) - r;
            sx += dx * dx;
            sy += dy * dy;
          }
        t.shift_x[std::size_t(k)] += sx;
        t.shift_y[std::size_t(k)] += sy;
      }
      const double n = double(edge.size()) * 3.0;
      t.sse_edge += se / n;
      t.sse_inner += si / n;
      const double mse = (se + si) / n;
      t.psnr_sum += mse > 0.0 ? -10.0 * std::log10(mse) : 1e9;
      ++t.frames;
    }
  }
  if (counted == 0) return fail("no frame after the warm-up", 1);
  const Test& base = tests.front();
  std::printf("Edge pixels (3x3 neighbourhood holds another surface): %.1f %% of the image, mean over %d frames "
              "after %d warm-up frames.\n\n",
              100.0 * edge_fraction / counted, counted, warmup);
  std::printf("| sequence | PSNR dB | error on edges | error in interiors | share on edges | edge error vs %s | "
              "interior error vs %s | best shift (dx, dy) px |\n|---|---|---|---|---|---|---|---|\n",
              base.name.c_str(), base.name.c_str());
  for (const auto& t : tests) {
    // The two errors are contributions to the frame's MSE (squared errors summed over those pixels and divided by
    // every pixel of the image): edges + interiors = MSE.
    const double e = t.sse_edge / t.frames, in = t.sse_inner / t.frames;
    const double be = base.sse_edge / base.frames, bi = base.sse_inner / base.frames;
    auto best = [](const std::vector<double>& v) {
      return shift_of(int(std::min_element(v.begin(), v.end()) - v.begin()));
    };
    std::printf("| %s | %.2f | %.3g | %.3g | %.0f %% | %+.0f %% | %+.0f %% | (%+.2f, %+.2f) |\n", t.name.c_str(),
                t.psnr_sum / t.frames, e, in, 100.0 * e / (e + in), 100.0 * (e / be - 1.0), 100.0 * (in / bi - 1.0),
                best(t.shift_x), best(t.shift_y));
  }
  return 0;
}
