// The worked example of docs/library.md: write a short noisy sequence, load it back frame by frame, filter it
// with PHLM (seed 003) and measure PSNR against the clean image before and after.
#include "temporal/io/exr.h"
#include "temporal/core/image.h"
#include "temporal/core/sequence.h"
#include "temporal/metrics/metrics.h"
#include "temporal/phlm/filters.h"

#include <cstdio>
#include <memory>
#include <random>
#include <string>
#include <vector>

using namespace temporal;

int main(int argc, char** argv) {
  const std::string dir = argc > 1 ? argv[1] : ".";
  const int w = 32, h = 24, frames = 16;
  // A static gradient with white noise, written as a sequence.
  Image clean(w, h);
  for (const char* c : {"R", "G", "B"}) {
    float* p = clean.add_channel(c);
    for (int i = 0; i < w * h; ++i) p[i] = 0.2f + 0.6f * float(i % w) / float(w);
  }
  std::mt19937 rng(1);
  std::normal_distribution<float> noise(0.0f, 0.05f);
  auto pattern = SequencePattern::parse(dir + "/noisy.####.exr");
  if (!pattern) return std::fprintf(stderr, "%s\n", pattern.error().message.c_str()), 1;
  for (int f = 0; f < frames; ++f) {
    Image noisy = clean;
    for (const char* c : {"R", "G", "B"})
      for (int i = 0; i < w * h; ++i) noisy.plane(c)[i] += noise(rng);
    if (Status s = write_exr(pattern->path(f), noisy); !s) return std::fprintf(stderr, "%s\n", s.error().message.c_str()), 1;
  }

  // The clean image too: docs/library.md's example (built beside this program) reads it.
  if (Status s = write_exr(dir + "/clean.exr", clean); !s) return std::fprintf(stderr, "%s\n", s.error().message.c_str()), 1;

  // Load the sequence back, filter it, measure the last frame.
  auto list = resolve_frames(*pattern, std::nullopt);
  if (!list) return std::fprintf(stderr, "%s\n", list.error().message.c_str()), 1;
  // Any method of filter-phlm by name, from the registry (temporal/phlm/filters.h), with its default parameters.
  auto made = phlm::make_filter(phlm::FilterOptions{.method = "phlm"});
  if (!made) return std::fprintf(stderr, "%s\n", made.error().message.c_str()), 1;
  std::unique_ptr<phlm::FrameFilter> filter = std::move(*made);
  Image output;
  double psnr_in = 0, psnr_out = 0;
  for (const int f : *list) {
    auto frame = read_exr(pattern->path(f), ExrSelection{{"rgb"}});
    if (!frame) return std::fprintf(stderr, "%s\n", frame.error().message.c_str()), 1;
    phlm::FilterInput in;
    in.color = &*frame;
    in.channels = {"R", "G", "B"};
    in.reset = f == list->front();
    if (Status s = filter->process(in, output); !s) return std::fprintf(stderr, "%s\n", s.error().message.c_str()), 1;
    const float* ref[] = {clean.plane("R"), clean.plane("G"), clean.plane("B")};
    const float* noisy[] = {frame->plane("R"), frame->plane("G"), frame->plane("B")};
    const float* filtered[] = {output.plane("R"), output.plane("G"), output.plane("B")};
    std::vector<std::uint8_t> valid(std::size_t(w) * h);  // pixels where both images are finite
    finite_mask(noisy, ref, valid.size(), valid.data());
    psnr_in = psnr_db(squared_error(noisy, ref, w, h, valid.data(), nullptr).all, 1.0);
    finite_mask(filtered, ref, valid.size(), valid.data());
    psnr_out = psnr_db(squared_error(filtered, ref, w, h, valid.data(), nullptr).all, 1.0);
  }
  std::printf("last frame: input %.2f dB, phlm %.2f dB\n", psnr_in, psnr_out);
  return psnr_out > psnr_in + 3.0 ? 0 : 1;
}
