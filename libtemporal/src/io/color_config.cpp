// Colour management through OpenColorIO 2.1 (no built-in config before 2.2: one is built here in code).
#include "temporal/io/color_config.h"

#include "temporal/core/image.h"
#include "temporal/core/parallel.h"

#include <OpenColorIO/OpenColorIO.h>

#include <cstdlib>
#include <sstream>

namespace OCIO = OCIO_NAMESPACE;

namespace temporal {

struct ColorConfig::Impl {
  OCIO::ConstConfigRcPtr config;
  std::string source;
};

namespace {

OCIO::ConstConfigRcPtr make_builtin_config() {
  OCIO::ConfigRcPtr config = OCIO::Config::Create();
  config->setMajorVersion(2);
  config->setMinorVersion(1);
  config->setDescription("temporal built-in config: scene-linear Rec.709 working space, sRGB and gamma 2.2 displays, YCgCo");

  auto linear = OCIO::ColorSpace::Create(OCIO::REFERENCE_SPACE_SCENE);
  linear->setName(colorspace::kSceneLinear);
  linear->setFamily("linear");
  linear->setDescription("Scene-linear Rec.709 primaries, D65: the working space of every tool");
  config->addColorSpace(linear);

  // sRGB OETF (IEC 61966-2-1): the forward ExponentWithLinear transform decodes to linear, so it is the
  // space's to-reference transform.
  auto srgb = OCIO::ColorSpace::Create(OCIO::REFERENCE_SPACE_SCENE);
  srgb->setName(colorspace::kSrgb);
  srgb->setFamily("display");
  srgb->setDescription("sRGB-encoded Rec.709 (piecewise 2.4 power with linear toe)");
  auto srgb_curve = OCIO::ExponentWithLinearTransform::Create();
  srgb_curve->setGamma({2.4, 2.4, 2.4, 1.0});
  srgb_curve->setOffset({0.055, 0.055, 0.055, 0.0});
  srgb->setTransform(srgb_curve, OCIO::COLORSPACE_DIR_TO_REFERENCE);
  config->addColorSpace(srgb);

  auto gamma = OCIO::ColorSpace::Create(OCIO::REFERENCE_SPACE_SCENE);
  gamma->setName(colorspace::kGamma22);
  gamma->setFamily("display");
  gamma->setDescription("Rec.709 encoded with a pure 1/2.2 power (a gamma-2.2 display)");
  auto power = OCIO::ExponentTransform::Create();
  power->setValue({2.2, 2.2, 2.2, 1.0});
  power->setNegativeStyle(OCIO::NEGATIVE_CLAMP);
  gamma->setTransform(power, OCIO::COLORSPACE_DIR_TO_REFERENCE);
  config->addColorSpace(gamma);

  // YCgCo (Malvar & Sullivan 2003), the same matrix as rgb_to_ycgco() in color.h.
  auto ycgco = OCIO::ColorSpace::Create(OCIO::REFERENCE_SPACE_SCENE);
  ycgco->setName(colorspace::kYCgCo);
  ycgco->setFamily("data");
  ycgco->setDescription("Linear YCgCo: Y = R/4 + G/2 + B/4, Cg = -R/4 + G/2 - B/4, Co = R/2 - B/2");
  auto matrix = OCIO::MatrixTransform::Create();
  const double m[16] = {0.25, 0.5, 0.25, 0, -0.25, 0.5, -0.25, 0, 0.5, 0, -0.5, 0, 0, 0, 0, 1};
  matrix->setMatrix(m);
  ycgco->setTransform(matrix, OCIO::COLORSPACE_DIR_FROM_REFERENCE);
  config->addColorSpace(ycgco);

  config->setRole(OCIO::ROLE_SCENE_LINEAR, colorspace::kSceneLinear);
  config->setRole(OCIO::ROLE_DEFAULT, colorspace::kSceneLinear);
  config->setRole(OCIO::ROLE_REFERENCE, colorspace::kSceneLinear);
  config->setRole(OCIO::ROLE_DATA, colorspace::kSceneLinear);
  config->addDisplayView("sRGB", "Standard", colorspace::kSrgb, "");
  config->addDisplayView("gamma22", "Standard", colorspace::kGamma22, "");
  config->setActiveDisplays("sRGB, gamma22");
  config->setActiveViews("Standard");
  config->validate();
  return config;
}

}  // namespace

ColorConfig::ColorConfig(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
ColorConfig::ColorConfig(ColorConfig&&) noexcept = default;
ColorConfig& ColorConfig::operator=(ColorConfig&&) noexcept = default;
ColorConfig::~ColorConfig() = default;

ColorConfig ColorConfig::builtin() {
  static const OCIO::ConstConfigRcPtr config = make_builtin_config();
  return ColorConfig(std::unique_ptr<Impl>(new Impl{config, "built-in"}));
}

Expected<ColorConfig> ColorConfig::load(const std::string& path) {
  std::string file = path;
  if (file.empty()) {
    const char* env = std::getenv("OCIO");
    if (env && *env) file = env;
  }
  if (file.empty()) return builtin();
  try {
    auto config = OCIO::Config::CreateFromFile(file.c_str());
    config->validate();
    return ColorConfig(std::unique_ptr<Impl>(new Impl{config, file}));
  } catch (const OCIO::Exception& e) {
    return Error::input(file, std::string("not a usable OpenColorIO config: ") + e.what() +
                                  " (fix the file, or unset $OCIO / drop --ocio to use the built-in config)");
  }
}

const std::string& ColorConfig::source() const { return impl_->source; }

std::vector<std::string> ColorConfig::color_spaces() const {
  std::vector<std::string> names;
  for (int i = 0; i < impl_->config->getNumColorSpaces(); ++i) names.emplace_back(impl_->config->getColorSpaceNameByIndex(i));
  return names;
}

std::string ColorConfig::serialize() const {
  std::ostringstream out;
  impl_->config->serialize(out);
  return out.str();
}

Expected<float> ColorConfig::display_gamma(const std::string& space) const {
  auto cs = impl_->config->getColorSpace(space.c_str());
  if (!cs) return Error::usage("no colour space '" + space + "' in the OCIO config " + source());
  auto t = cs->getTransform(OCIO::COLORSPACE_DIR_TO_REFERENCE);
  if (auto e = OCIO::DynamicPtrCast<const OCIO::ExponentTransform>(t)) {
    double v[4];
    e->getValue(v);
    return float(v[0]);
  }
  // The sRGB curve (2.4 power with a linear toe) is closest to a pure 2.2 power over [0, 1]; formulas that
  // need one exponent use that.
  if (OCIO::DynamicPtrCast<const OCIO::ExponentWithLinearTransform>(t)) return 2.2f;
  return Error::usage("colour space '" + space + "' is not a power-law display encoding; give --gamma instead");
}

Status ColorConfig::convert(Image& image, std::span<const std::string> rgb_channels, const std::string& from,
                            const std::string& to) const {
  if (rgb_channels.size() != 3) return Error::internal("ColorConfig::convert needs exactly three channels");
  float* planes[3];
  for (int c = 0; c < 3; ++c) {
    planes[c] = image.plane(rgb_channels[c]);
    if (!planes[c]) return Error::internal("ColorConfig::convert: no float channel '" + rgb_channels[c] + "'");
  }
  OCIO::ConstCPUProcessorRcPtr cpu;
  try {
    cpu = impl_->config->getProcessor(from.c_str(), to.c_str())->getDefaultCPUProcessor();
  } catch (const OCIO::Exception& e) {
    return Error::usage("cannot convert from '" + from + "' to '" + to + "': " + e.what());
  }
  const int w = image.width();
  std::string failure;
  parallel_rows(image.height(), [&](int y0, int y1) {
    const std::size_t offset = std::size_t(y0) * w;
    OCIO::PlanarImageDesc desc(planes[0] + offset, planes[1] + offset, planes[2] + offset, nullptr, w, y1 - y0);
    try {
      cpu->apply(desc);
    } catch (const OCIO::Exception& e) {
      failure = e.what();
    }
  }, 16);
  if (!failure.empty()) return Error::internal("OpenColorIO: " + failure);
  return {};
}

Expected<float> load_display_gamma(const std::string& space, const std::string& config_path) {
  auto config = ColorConfig::load(config_path);
  if (!config) return config.error();
  return config->display_gamma(space);
}

}  // namespace temporal
