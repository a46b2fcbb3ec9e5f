// FLIP: a perceptual difference map between a test image and its reference, as an observer flipping between
// them would see it. LDR-FLIP: Andersson, Nilsson, Akenine-Möller, Oskarsson, Åström, Fairchild, "FLIP: A
// Difference Evaluator for Alternating Images", HPG 2020 (PACMCGIT 3(2), article 15). HDR-FLIP: Andersson,
// Nilsson, Shirley, Akenine-Möller, "Visualizing Errors in Rendered High Dynamic Range Images", Eurographics
// 2021 (short paper). Implemented from the papers with every constant, filter and normalisation as NVIDIA's
// reference implementation v1.6 (NVlabs/flip, `FLIP.h`) has them; docs/compare.md gives the agreement measured
// against that tool and the cost.
//
// Units and conventions
//   - Images are planar RGB: three planes of width * height floats, row-major, no padding.
//   - LDR-FLIP takes display-encoded values: sRGB-encoded R'G'B' in [0, 1] (FlipLdrInput::Srgb, what an 8-bit
//     PNG holds divided by 255), linearised with the sRGB EOTF; or linear values (FlipLdrInput::Linear), used
//     as they are. Either way the linear values are clamped to [0, 1] first, as the reference does.
//   - HDR-FLIP takes scene-linear Rec.709 RGB (any non-negative range). It exposes both images by 2^e for
//     several exposures e (stops), tone-maps them to [0, 1] and takes the per-pixel maximum of LDR-FLIP over
//     the exposures (the HDR-FLIP paper's exposure range).
//   - The viewing condition is pixels per degree of visual angle (temporal/core/viewing.h); the default,
//     67.0206, is FLIP's: 0.7 m from a 0.7 m wide 3840-pixel screen.
//   - The map holds one FLIP value per pixel in [0, 1] (0: no perceived difference).
//   - Image borders are extended by clamping coordinates (the reference's rule); no border pixel is dropped.
//   - Pixels marked invalid (`valid[i] == 0`, e.g. NaN or Inf in either image) are set to black in both images
//     before filtering, so they never spread NaN; their map value is 0 and pooling skips them.
//
// The pipeline, per image (the 2020 paper's colour pipeline, feature pipeline and final error; NVIDIA's code
// for the exact normalisations):
//   1. Colour pipeline. Linear RGB -> CIE XYZ (D65) -> YyCxCz, the linearised CIELab space of Flohr et al.:
//        Y = 116 Y/Yn - 16, Cx = 500 (X/Xn - Y/Yn), Cz = 200 (Y/Yn - Z/Zn).
//      Each channel is filtered with the contrast sensitivity function of the human visual system expressed
//      as Gaussians in the spatial domain ("spatial filtering"):
//        s(x) = a1 sqrt(pi / b1) exp(-pi^2 x^2 / b1) + a2 sqrt(pi / b2) exp(-pi^2 x^2 / b2), x in degrees,
//      with the parameters of FlipCsf below; the 2-D kernel is normalised to sum 1, sampled every 1/ppd degrees
//      over a radius of ceil(3 sqrt(max b / (2 pi^2)) ppd) pixels. Y and Cx use one Gaussian (separable); Cz's
//      sum of two Gaussians is filtered as two separable passes that are added. (The evaluator skips the outer
//      taps of the narrow Y and Cx kernels that are below 2^-24 of their centre tap: they change a filtered
//      value by less than its float rounding.) The filtered colour goes back
//      to linear RGB, is clamped to [0, 1], and is converted to CIELab with the Hunt adjustment
//        a' = 0.01 L a, b' = 0.01 L b      (chroma perceived lower at low luminance)
//      The colour difference is HyAB (Abasi et al. 2020), |L1 - L2| + sqrt((a1' - a2')^2 + (b1' - b2')^2),
//      raised to q_c = 0.7 and re-mapped to [0, 1] with the knee p_c = 0.4 of the largest difference c_max
//      (HyAB^q_c between Hunt-adjusted pure green and pure blue) and p_t = 0.95:
//        e_c = e * p_t / (p_c c_max)                                      for e <  p_c c_max
//        e_c = p_t + (e - p_c c_max) / (c_max - p_c c_max) * (1 - p_t)    otherwise.
//   2. Feature pipeline on the achromatic channel normalised to [0, 1], (Y + 16) / 116: first and
//      second derivatives of a Gaussian with sigma = 0.5 w ppd pixels (w = 0.082 degrees), radius ceil(3
//      sigma), each derivative kernel scaled so its positive weights sum to 1 and its negative ones to -1. Edge
//      magnitude |grad|, point magnitude |second derivatives|; the feature difference is
//        e_f = ( max(|edge_t - edge_r|, |point_t - point_r|) / sqrt(2) )^q_f,   q_f = 0.5.
//   3. FLIP = e_c^(1 - e_f): feature differences raise the colour error towards 1.
//
// HDR-FLIP exposures (2021 paper): unless given, the start exposure is log2(x_max / Y_max) and the
// stop exposure log2(x_max / Y_median), where Y is the reference's Rec.709 luminance and x_max the input that
// the tone mapper maps to 0.85; the number of exposures is max(2, ceil(stop - start)), evenly spaced. Where the
// reference's median luminance is 0 (more than half the pixels black) the smallest positive luminance stands
// in for it, and a reference without any positive luminance uses exposure 0 (the reference tool would divide
// by zero in both cases).
//
// Pooling as NVIDIA's tool reports it (`pooling.h`): the mean over pixels, and weighted percentiles: with the
// valid values sorted ascending, the p-th weighted percentile is the first value at which the running sum of
// values exceeds p times their total (each value weighs as much as its own size, so large errors dominate).
#pragma once

#include "temporal/core/error.h"
#include "temporal/core/viewing.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

namespace temporal {

// Which FLIP: LDR-FLIP for display-referred images, HDR-FLIP for scene-linear ones.
enum class FlipRange { Ldr, Hdr };

// How LDR-FLIP reads its inputs: sRGB-encoded values in [0, 1] (linearised with the sRGB EOTF, as NVIDIA's tool
// does with PNG files), or values that are already linear (the sRGB round trip skipped: same result up to float
// rounding).
enum class FlipLdrInput { Srgb, Linear };

// HDR-FLIP's tone mapper (applied per channel to the exposed linear values, then clamped to [0, 1]). ACES is
// Narkowicz's fit of the ACES filmic curve with a 0.6 pre-exposure cancelled, FLIP's default; Reinhard is
// c / (1 + Y); Hable is a rational fit of Hable's Uncharted 2 curve (the reference's coefficients).
enum class FlipToneMapper { Aces, Reinhard, Hable };

struct FlipOptions {
  double pixels_per_degree = kFlipDefaultPixelsPerDegree;  // viewing condition, > 0
  FlipLdrInput ldr_input = FlipLdrInput::Srgb;             // LDR-FLIP only
  FlipToneMapper tone_mapper = FlipToneMapper::Aces;       // HDR-FLIP only
  std::optional<float> start_exposure;  // HDR-FLIP, stops; empty: automatic from the reference
  std::optional<float> stop_exposure;   // HDR-FLIP, stops; empty: automatic from the reference
  int exposures = 0;                    // HDR-FLIP; 0: automatic, max(2, ceil(stop - start)); else >= 2
};

// Three planes of width * height floats (R, G, B). For a grey image pass the same plane three times.
struct FlipImage {
  const float* r = nullptr;
  const float* g = nullptr;
  const float* b = nullptr;
};

// The exposures HDR-FLIP evaluated: `count` values evenly spaced from `start` to `stop` (stops).
struct FlipExposures {
  float start = 0.0f;
  float stop = 0.0f;
  int count = 0;
};

// Pooled values of a FLIP map over its valid pixels (NaN when there is none).
struct FlipStats {
  double mean = 0.0;
  double weighted_median = 0.0;      // weighted percentile 0.5 (see the pooling rule above)
  double weighted_quartile_1 = 0.0;  // weighted percentile 0.25
  double weighted_quartile_3 = 0.0;  // weighted percentile 0.75
  double min = 0.0;
  double max = 0.0;
  std::size_t pixels = 0;  // valid pixels pooled
};

// Computes FLIP maps. Keeps its scratch planes (about 20 planes of the image size) between calls, so a caller
// that measures many frames allocates once; every per-pixel loop is parallel over rows (oneTBB, honouring
// ThreadLimit) and unit-stride. Not thread-safe: use one evaluator per thread.
class FlipEvaluator {
 public:
  explicit FlipEvaluator(FlipOptions options = {});
  ~FlipEvaluator();
  FlipEvaluator(FlipEvaluator&&) noexcept;
  FlipEvaluator& operator=(FlipEvaluator&&) noexcept;

  const FlipOptions& options() const { return options_; }

  // Writes the LDR-FLIP map of `test` against `reference` (width * height floats) to `map`. `valid` may be
  // null (every pixel valid). Error (Usage) for bad options, (Input) for an empty image or a missing plane.
  Status ldr(const FlipImage& test, const FlipImage& reference, int width, int height, const std::uint8_t* valid,
             float* map);

  // Writes the HDR-FLIP map (per-pixel maximum of LDR-FLIP over the exposures) to `map` and returns the
  // exposures used. `exposure_map` (may be null) receives, per pixel, the index of the exposure that gave the
  // maximum divided by (count - 1), in [0, 1] (the reference's exposure map).
  Expected<FlipExposures> hdr(const FlipImage& test, const FlipImage& reference, int width, int height,
                              const std::uint8_t* valid, float* map, float* exposure_map = nullptr);

 private:
  struct Workspace;
  FlipOptions options_;
  std::unique_ptr<Workspace> work_;
};

// The mean and weighted percentiles of `map` over the pixels with valid[i] != 0 (all when `valid` is null).
// Exact (no histogram approximation): values are bucketed to find the three percentiles, and only the values
// of the buckets that hold them are sorted. Sums in double precision.
FlipStats flip_statistics(std::span<const float> map, const std::uint8_t* valid = nullptr);

// One-call forms: the map (when `map` is not null), its statistics over all pixels, and for HDR-FLIP the
// exposures used (`exposures` may be null).
Expected<FlipStats> evaluate_flip(FlipRange range, const FlipImage& test, const FlipImage& reference, int width,
                                  int height, const FlipOptions& options = {}, float* map = nullptr,
                                  FlipExposures* exposures = nullptr);

// --- The building blocks, exposed for tests and for callers that need one step ---------------------------
namespace flip {

// Constants of the 2020 paper as NVIDIA's code has them.
inline constexpr float kQc = 0.7f;    // colour difference exponent q_c
inline constexpr float kPc = 0.4f;    // re-mapping knee, as a fraction of c_max
inline constexpr float kPt = 0.95f;   // re-mapped value at the knee
inline constexpr float kW = 0.082f;   // feature detector width, degrees (sigma = 0.5 w ppd pixels)
inline constexpr float kQf = 0.5f;    // feature difference exponent q_f

// Contrast sensitivity functions as sums of Gaussians, s(x) = a1 sqrt(pi/b1) exp(-pi^2 x^2/b1) + a2 sqrt(pi/b2)
// exp(-pi^2 x^2/b2), x in degrees: {Y, Cx, Cz}. Y and Cx have a2 = 0.
struct FlipCsf {
  float a1, b1, a2, b2;
};
inline constexpr FlipCsf kCsf[3] = {
    {1.0f, 0.0047f, 0.0f, 1.0e-5f},    // achromatic Y
    {1.0f, 0.0053f, 0.0f, 1.0e-5f},    // red-green Cx
    {34.1f, 0.04f, 13.5f, 0.025f},     // blue-yellow Cz
};

using Color = std::array<float, 3>;

// sRGB EOTF (IEC 61966-2-1): encoded value in [0, 1] -> linear.
float srgb_to_linear(float encoded);
// Linear Rec.709 RGB -> CIE XYZ (D65 white, Y of white = 1), the reference's exact rational matrix.
Color linear_rgb_to_xyz(const Color& rgb);
Color xyz_to_linear_rgb(const Color& xyz);
// XYZ -> YyCxCz (linearised CIELab: the cube root of CIELab left out) and back, D65 white (0.950428545, 1,
// 1.088900371).
Color xyz_to_ycxcz(const Color& xyz);
Color ycxcz_to_xyz(const Color& ycxcz);
// XYZ -> CIELab (D65 white).
Color xyz_to_lab(const Color& xyz);
// Hunt adjustment of a CIELab colour: (L, 0.01 L a, 0.01 L b).
Color hunt_adjust(const Color& lab);
// HyAB distance: |L1 - L2| + sqrt((a1 - a2)^2 + (b1 - b2)^2).
float hyab(const Color& lab1, const Color& lab2);
// c_max: HyAB^q_c between the Hunt-adjusted CIELab of linear pure green (0, 1, 0) and pure blue (0, 0, 1).
float max_color_difference();
// HyAB -> the colour error in [0, 1]: HyAB^q_c re-mapped with the knee (p_c c_max, p_t).
float remap_color_difference(float hyab_distance);
// Feature difference from the edge and point magnitudes of the test and the reference.
float feature_difference(float edge_test, float point_test, float edge_reference, float point_reference);
// FLIP = color^(1 - feature).
float combine(float color_difference, float feature_difference);
// HDR-FLIP tone mapping of one exposed linear colour (not clamped).
Color tone_map(FlipToneMapper tone_mapper, const Color& rgb);
// The automatic exposures of HDR-FLIP for `reference` (`count` pixels; invalid pixels, when `valid` is given,
// count as black).
FlipExposures automatic_exposures(const FlipImage& reference, std::size_t count, FlipToneMapper tone_mapper,
                                  const std::uint8_t* valid = nullptr);

// Radius in pixels of the colour (CSF) filters and of the feature filters at `pixels_per_degree`.
int spatial_filter_radius(double pixels_per_degree);
int feature_filter_radius(double pixels_per_degree);

// The 1-D taps (2 radius + 1 each) of the separable CSF filters: y and cx sum to 1; cz1 and cz2 are scaled by
// 1 / sqrt(sum(cz1)^2 + sum(cz2)^2), so that the 2-D kernel cz1 (x) cz1 + cz2 (x) cz2 sums to 1.
struct SpatialFilters {
  std::vector<float> y, cx, cz1, cz2;
};
SpatialFilters spatial_filters(double pixels_per_degree);

// The 1-D taps of the feature filters: the Gaussian (sums to 1) and its first and second derivatives (positive
// weights sum to 1, negative weights to -1).
struct FeatureFilters {
  std::vector<float> g, dg, ddg;
};
FeatureFilters feature_filters(double pixels_per_degree);

}  // namespace flip
}  // namespace temporal
