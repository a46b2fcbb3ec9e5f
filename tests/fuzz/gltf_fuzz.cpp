// libFuzzer target: the glTF reader (tinygltf's parser, then this project's validation and conversion of the
// model) through Scene::load, and the evaluation of what loads at a few times.
#include "fuzz_support.h"

#include "temporal/scene/scene.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // .glb and .gltf are told apart by content; the name only keeps the USD sniffing out of the way.
  auto scene = temporal::Scene::load(temporal::fuzz::write_input(data, size, "input.gltf"));
  if (!scene) return 0;
  temporal::FrameState state;
  for (double t : {0.0, 0.37, 5.0}) scene->evaluate(t, state);
  return 0;
}
