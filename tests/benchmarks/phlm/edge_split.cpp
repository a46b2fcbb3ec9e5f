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
// Shift: per axis, the least-squares translation s of the output against the reference (Lucas-Kanade, linearised:
// out(x) ~ ref(x - s), so s = -sum (out - ref) dref/dx / sum (dref/dx)^2, central differences, luminance), summed
// over the image less a 2-pixel margin and over the frames after the warm-up. Blur is even about an edge and the
// gradient odd, so a blurred or noisy output gives s ~ 0; a half-pixel convention mismatch gives |s| ~ 0.5. (A search
// over resampled shifts would not do: resampling blurs, and blurring an aliased image lowers its error.)
// The first test is the baseline of the relative columns (give the unfiltered input first), and the subject of the
// convention fit: per frame, its shift against its temporal:jitter (see the end of main).
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
  double num[2] = {}, den[2] = {};  // Lucas-Kanade sums per axis
  // Per frame (every frame): the frame's own shift and its temporal:jitter, for the convention fit of the input.
  std::vector<double> frame_shift[2], frame_jitter[2];
};

// Least-squares line y = a + b x.
void fit(const std::vector<double>& x, const std::vector<double>& y, double& a, double& b) {
  const double n = double(x.size());
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    sx += x[i];
    sy += y[i];
    sxx += x[i] * x[i];
    sxy += x[i] * y[i];
  }
  const double d = n * sxx - sx * sx;
  b = d != 0.0 ? (n * sxy - sx * sy) / d : 0.0;
  a = (sy - b * sx) / n;
}

double luma(const Image& img, std::size_t i) {
  return 0.2126 * img.plane("R")[i] + 0.7152 * img.plane("G")[i] + 0.0722 * img.plane("B")[i];
}

int fail(const std::string& text, int code) {
  std::fprintf(stderr, "phlm_edge_split: %s\n", text.c_str());
  return code;
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
      tests.push_back(Test{a.substr(0, a.find('=')), *pattern, 0, 0, 0, 0, {}, {}, {}, {}});
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
  int counted = 0, width = 0, height = 0;
  const reproject::SurfaceTest rule{};
  for (std::size_t f = 0; f < frames->size(); ++f) {
    const int frame = (*frames)[f];
    auto ref = read_exr(ref_pattern->path(frame), {{"rgb"}});
    if (!ref) return fail(ref.error().message, 2);
    auto g = read_exr(g_pattern->path(frame), {{"depth", "id"}});
    if (!g) return fail(g.error().message, 2);
    const int w = ref->width(), h = ref->height();
    width = w;
    height = h;
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
      double num[2] = {}, den[2] = {};
      for (int y = 2; y < h - 2; ++y)
        for (int x = 2; x < w - 2; ++x) {
          const std::size_t i = std::size_t(y) * std::size_t(w) + std::size_t(x);
          const double d = double(ly[i]) - double(lr[i]);
          const double gx = 0.5 * (double(lr[i + 1]) - double(lr[i - 1]));
          const double gy = 0.5 * (double(lr[i + std::size_t(w)]) - double(lr[i - std::size_t(w)]));
          num[0] -= d * gx;
          den[0] += gx * gx;
          num[1] -= d * gy;
          den[1] += gy * gy;
        }
      const glm::vec2 jitter = img->metadata().jitter.value_or(glm::vec2(0.0f));
      for (int axis = 0; axis < 2; ++axis) {
        t.frame_shift[axis].push_back(den[axis] > 0.0 ? num[axis] / den[axis] : 0.0);
        t.frame_jitter[axis].push_back(jitter[axis]);
      }
      if (!steady) continue;
      for (int axis = 0; axis < 2; ++axis) {
        t.num[axis] += num[axis];
        t.den[axis] += den[axis];
      }
      const double n = double(edge.size()) * 3.0;
      if (!steady) continue;
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
              "interior error vs %s | shift (dx, dy) px |\n|---|---|---|---|---|---|---|---|\n",
              base.name.c_str(), base.name.c_str());
  for (const auto& t : tests) {
    // The two errors are contributions to the frame's MSE (squared errors summed over those pixels and divided by
    // every pixel of the image): edges + interiors = MSE.
    const double e = t.sse_edge / t.frames, in = t.sse_inner / t.frames;
    const double be = base.sse_edge / base.frames, bi = base.sse_inner / base.frames;
    auto shift = [&](int axis) { return t.den[axis] > 0.0 ? t.num[axis] / t.den[axis] : 0.0; };
    std::printf("| %s | %.2f | %.3g | %.3g | %.0f %% | %+.0f %% | %+.0f %% | (%+.2f, %+.2f) |\n", t.name.c_str(),
                t.psnr_sum / t.frames, e, in, 100.0 * e / (e + in), 100.0 * (e / be - 1.0), 100.0 * (in / bi - 1.0),
                shift(0), shift(1));
  }
  // The convention check on the first sequence (the jittered input): a frame jittered by j shows the scene at
  // x + j, so against a reference centred on the pixel its shift is s = c - j, c the reference's own offset. The
  // fit s = a + b j over all frames: b = -1 when the jitter's sign and units are those of the header, a = c.
  double a[2], b[2];
  for (int axis = 0; axis < 2; ++axis) fit(base.frame_jitter[axis], base.frame_shift[axis], a[axis], b[axis]);
  std::printf("\nConvention fit on %s, per frame shift s = a + b * jitter over %zu frames: x: a = %+.3f px, b = %+.2f; "
              "y: a = %+.3f px, b = %+.2f (expected b = -1, a = the reference's offset).\n",
              base.name.c_str(), base.frame_shift[0].size(), a[0], b[0], a[1], b[1]);
  // What an offset (a_x, a_y) of the reference costs a perfectly converged output, to first order: the luminance
  // MSE a_x^2 <(dref/dx)^2> + a_y^2 <(dref/dy)^2> (mean over the pixels and frames of the steady state).
  const double pixels = double(counted) * double(width - 4) * double(height - 4);
  const double offset_mse = (a[0] * a[0] * base.den[0] + a[1] * a[1] * base.den[1]) / pixels;
  std::printf("That offset alone would cost a converged output a luminance MSE of %.3g, i.e. cap its PSNR (Y) at "
              "%.1f dB.\n", offset_mse, offset_mse > 0.0 ? -10.0 * std::log10(offset_mse) : INFINITY);
  return 0;
}
