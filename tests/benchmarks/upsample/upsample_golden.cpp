// Regression helper for optimisation work on one machine (not a test: float bits differ across CPUs with
// -march=native and FMA; tests/upsample/reference_test.cpp is the check CTest runs): runs the variants of kNames
// (the method table's, in the order of the file) on synthetic sequences (the benchmark's 1280x1024 pan; small
// scenes with a moving object and per-frame G-buffers, debug layers on, k = 4, 3 (odd width) and 2 (gradient
// scale 4)) and writes every output float to FILE (`write FILE`), or compares against FILE (`check FILE`), printing
// the largest absolute and relative differences per variant ("max abs 0": bit-identical) and, for a variant that
// differs, per scene and output channel (payload or debug layer) with the PSNR against the stored run.
#include "synthetic.h"
#include "upsample_variants.h"

#include "temporal/upsample/upsample.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace up = temporal::upsample;
using temporal::Image;

namespace {

const std::vector<std::string> kRGB = {"R", "G", "B"};

// The variants of the file, in its order (the file has no names: a file written before a variant was added stays
// comparable). Each must be a variant of the method table.
const char* const kNames[] = {"spatial", "temporal", "herzog", "drobot", "drobot-refresh", "herzog-lagged", "taau"};
constexpr int kVariants = int(std::size(kNames));

up::Options options(int m, std::vector<std::string> extra = {}) {
  return temporal::test::upsample_variant(kNames[m], std::move(extra));
}

// Where each plane lies in a variant's floats (the same for `write` and `check`): its scene and channel, so that
// `check` can say which outputs moved (payload or debug layer, which scene).
struct Segment {
  int scene;
  std::string channel;
  std::size_t begin, end;
};
const char* const kScenes[] = {"pan 1280x1024", "small k=4", "k=3", "k=2"};

void append(std::vector<float>& v, std::vector<Segment>& seg, int scene, const Image& img) {
  for (const auto& n : img.channel_names()) {
    const float* p = img.plane(n);
    if (!p) continue;
    seg.push_back({scene, n, v.size(), v.size() + img.pixel_count()});
    v.insert(v.end(), p, p + img.pixel_count());
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: upsample_golden write|check FILE\n");
    return 1;
  }
  const bool write = std::strcmp(argv[1], "write") == 0;
  // Scene A: the benchmark's (one G-buffer for every frame).
  temporal::test::SyntheticScene a;
  a.width = 1280;
  a.height = 1024;
  a.k = 4;
  a.period = 37.0f;
  a.camera_velocity = {1.25f, 0.5f};
  a.object = true;
  a.object_start = {400.0f, 300.0f};
  a.object_size = 300;
  std::vector<temporal::test::SyntheticFrame> fa;
  for (int t = 1; t <= 16; ++t) fa.push_back(temporal::test::make_frame(a, t));
  // Scene B: small, moving object, per-frame G-buffers.
  temporal::test::SyntheticScene b;
  b.width = 256;
  b.height = 192;
  b.k = 4;
  b.camera_velocity = {0.75f, -0.5f};
  b.object = true;
  b.object_start = {40.0f, 30.0f};
  b.object_velocity = {2.5f, 1.5f};
  b.object_size = 50;
  std::vector<temporal::test::SyntheticFrame> fb;
  for (int t = 1; t <= 24; ++t) fb.push_back(temporal::test::make_frame(b, t));

  // Scenes C and D: other factors, an odd width, another gradient scale and an integer mip level.
  temporal::test::SyntheticScene k3 = b;
  k3.width = 99;
  k3.height = 75;
  k3.k = 3;
  temporal::test::SyntheticScene k2 = b;
  k2.width = 128;
  k2.height = 96;
  k2.k = 2;
  std::vector<temporal::test::SyntheticFrame> fc, fd;
  for (int t = 1; t <= 12; ++t) {
    fc.push_back(temporal::test::make_frame(k3, t));
    fd.push_back(temporal::test::make_frame(k2, t));
  }

  std::vector<std::vector<float>> results(kVariants);
  std::vector<std::vector<Segment>> segments(kVariants);
  for (int m = 0; m < kVariants; ++m) {
    {
      up::Upsampler u(options(m));
      for (int i = 0; i < 40; ++i) {
        auto r = u.process(fa[0].gbuffer, fa[i % 16].low, kRGB, false);
        if (!r) return 2;
        if (i >= 36) append(results[m], segments[m], 0, **r);
      }
    }
    {
      up::Upsampler u(options(m, {"--debug-layers"}));
      for (int i = 0; i < 24; ++i) {
        auto r = u.process(fb[i].gbuffer, fb[i].low, kRGB, false);
        if (!r) return 2;
        append(results[m], segments[m], 1, **r);
      }
    }
    for (int scene = 0; scene < 2; ++scene) {
      std::vector<std::string> extra = {"--debug-layers"};
      if (scene == 1) extra.insert(extra.end(), {"--gradient-scale", "4", "--gradient-mip-level", "3"});
      up::Upsampler u(options(m, extra));
      const auto& frames = scene == 0 ? fc : fd;
      for (const auto& fr : frames) {
        auto r = u.process(fr.gbuffer, fr.low, kRGB, false);
        if (!r) return 2;
        append(results[m], segments[m], 2 + scene, **r);
      }
    }
  }
  if (write) {
    std::ofstream f(argv[2], std::ios::binary);
    for (auto& v : results) {
      const std::uint64_t n = v.size();
      f.write(reinterpret_cast<const char*>(&n), sizeof n);
      f.write(reinterpret_cast<const char*>(v.data()), std::streamsize(n * sizeof(float)));
    }
    return f ? 0 : 3;
  }
  std::ifstream f(argv[2], std::ios::binary);
  int bad = 0;
  for (int m = 0; m < kVariants; ++m) {
    std::uint64_t n = 0;
    f.read(reinterpret_cast<char*>(&n), sizeof n);
    std::vector<float> ref(n);
    f.read(reinterpret_cast<char*>(ref.data()), std::streamsize(n * sizeof(float)));
    if (n != results[m].size()) {
      std::printf("%-18s size mismatch %zu vs %zu\n", kNames[m], std::size_t(n), results[m].size());
      ++bad;
      continue;
    }
    double max_abs = 0, max_rel = 0;
    std::size_t nan_mismatch = 0, differing = 0, first = n;
    for (std::size_t i = 0; i < n; ++i) {
      const float x = results[m][i], y = ref[i];
      if (std::isnan(x) != std::isnan(y)) ++nan_mismatch;
      if (std::isnan(x) || std::isnan(y)) continue;
      const double d = std::abs(double(x) - double(y));
      if (d > 0) {
        first = std::min(first, i);
        ++differing;
      }
      max_abs = std::max(max_abs, d);
      max_rel = std::max(max_rel, d / std::max(1.0, std::abs(double(y))));
    }
    const bool ok = max_rel <= 1e-4 && nan_mismatch == 0;
    bad += ok ? 0 : 1;
    std::printf("%-18s max abs %.3g  max rel %.3g  nan mismatch %zu  %s", kNames[m], max_abs, max_rel, nan_mismatch,
                ok ? "OK" : "DIFFERENT");
    if (differing) std::printf("  (%zu values differ, the first at float %zu of %zu)", differing, first, std::size_t(n));
    std::printf("\n");
    if (!differing) continue;
    // Per scene and channel: the largest difference (absolute; relative to max(1, |reference|)) and the PSNR of
    // the output against the reference, 10 log10(peak^2 / MSE) with peak the largest |reference| of the channel.
    struct Diff {
      double max_abs = 0, max_rel = 0, sq = 0, peak = 0;
      std::size_t n = 0;
    };
    std::vector<std::pair<std::string, Diff>> per;
    for (const Segment& sg : segments[m]) {
      const std::string key = std::string(kScenes[sg.scene]) + " " + sg.channel;
      auto it = std::find_if(per.begin(), per.end(), [&](const auto& e) { return e.first == key; });
      if (it == per.end()) it = per.insert(per.end(), {key, Diff{}});
      Diff& e = it->second;
      for (std::size_t i = sg.begin; i < sg.end; ++i) {
        const float x = results[m][i], y = ref[i];
        if (std::isnan(x) || std::isnan(y)) continue;
        const double d = std::abs(double(x) - double(y));
        e.max_abs = std::max(e.max_abs, d);
        e.max_rel = std::max(e.max_rel, d / std::max(1.0, std::abs(double(y))));
        e.sq += d * d;
        e.peak = std::max(e.peak, std::abs(double(y)));
        ++e.n;
      }
    }
    for (const auto& [key, e] : per)
      if (e.max_abs > 0)
        std::printf("    %-36s max abs %.3g  max rel %.3g  PSNR %.1f dB\n", key.c_str(), e.max_abs, e.max_rel,
                    10.0 * std::log10(e.peak * e.peak / (e.sq / double(e.n))));
  }
  return bad ? 4 : 0;
}
