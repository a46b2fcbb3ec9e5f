// The FrameContext of an upsampling method for a synthetic frame, built as Upsampler::build_context and
// depth_scales build it (R, G, B payload), for the GPU tests and the GPU benchmark that run method states directly.
#pragma once

#include "method.h"  // libtemporal/src/upsample (internal)
#include "synthetic.h"  // tests/upsample

#include <cmath>
#include <string>
#include <vector>

namespace temporal::test {

inline void build_context(upsample::FrameContext& f, const upsample::Options& o, const SyntheticFrame& fr,
                          bool warped, bool debug) {
  using namespace temporal::upsample;
  static const std::vector<std::string> kRgb = {"R", "G", "B"};
  const FrameMetadata& lm = fr.low.metadata();
  const int k = *lm.jitter_factor;
  const int sx = int(std::lround((lm.jitter->x + 0.5f) * k - 0.5f)), sy = int(std::lround((lm.jitter->y + 0.5f) * k - 0.5f));
  f.options = &o;
  f.debug = debug;
  f.W = fr.gbuffer.width();
  f.H = fr.gbuffer.height();
  f.lw = fr.low.width();
  f.lh = fr.low.height();
  f.grid = {k, sx, sy};
  f.C = 3;
  f.low.clear();
  for (const auto& c : kRgb) f.low.push_back(fr.low.plane(c));
  f.z = fr.gbuffer.plane("depth.Z");
  f.nx = fr.gbuffer.plane("N.X");
  f.ny = fr.gbuffer.plane("N.Y");
  f.nz = fr.gbuffer.plane("N.Z");
  f.mx = fr.gbuffer.plane("motion.X");
  f.my = fr.gbuffer.plane("motion.Y");
  f.id = fr.gbuffer.uint_plane("id");
  // The synthetic surfaces are fronto-parallel: the warped depth equals the depth (exercises the warped rule).
  f.prev_z = warped ? f.z : nullptr;
  const FrameMetadata& gm = fr.gbuffer.metadata();
  f.depth_range = *gm.far_clip - *gm.near_clip;
  f.sigma_d = o.sigma_depth_fraction * f.depth_range;
  f.luma.assign(3, 1.0f / 3.0f);
  f.cols.build(f.W, f.lw, k, sx);
  f.rows.build(f.H, f.lh, k, sy);
  gather_low_geometry(f);
}

inline upsample::Geometry geometry_of(const SyntheticFrame& fr) {
  using namespace temporal::upsample;
  static const std::vector<std::string> kRgb = {"R", "G", "B"};
  Geometry g;
  g.W = fr.gbuffer.width();
  g.H = fr.gbuffer.height();
  g.k = *fr.low.metadata().jitter_factor;
  g.lw = fr.low.width();
  g.lh = fr.low.height();
  g.channels = kRgb;
  return g;
}

}  // namespace temporal::test
