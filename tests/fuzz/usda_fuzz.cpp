// libFuzzer target: the .usda parser on every input, and the whole USD scene reader (composition, UsdGeom,
// UsdShade, UsdLux, UsdSkel, evaluation at a few times) on every input that parses.
#include "fuzz_support.h"

#include "temporal/scene/scene.h"
#include "usd_layer.h"

#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  auto layer = temporal::usd::parse_usda(text, (temporal::fuzz::scratch() / "input.usda").string());
  if (!layer) return 0;
  auto scene = temporal::Scene::load(temporal::fuzz::write_input(data, size, "input.usda"));
  if (!scene) return 0;
  temporal::FrameState state;
  for (double t : {0.0, 0.37, 5.0}) scene->evaluate(t, state);
  return 0;
}
