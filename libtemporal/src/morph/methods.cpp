// The registry of morph-120hz's methods (temporal/morph/methods.h): one line per method.
#include "temporal/morph/methods.h"

namespace temporal {

// Each method's entry, defined in its own source file.
MorphMethodInfo didyk_method();   // didyk.cpp: seed 004
MorphMethodInfo repeat_method();  // repeat.cpp
MorphMethodInfo blend_method();   // blend.cpp
MorphMethodInfo warp_method();    // warp.cpp

std::span<const MorphMethodInfo> morph_methods() {
  static const std::vector<MorphMethodInfo> table = {
      didyk_method(),
      repeat_method(),
      blend_method(),
      warp_method(),
  };
  return table;
}

Expected<const MorphMethodInfo*> find_morph_method(std::string_view name) {
  std::string names;
  for (const auto& m : morph_methods()) {
    if (m.name == name) return &m;
    names += (names.empty() ? "" : ", ") + m.name;
  }
  return Error::usage("unknown method '" + std::string(name) + "': use one of " + names);
}

std::vector<std::string> morph_gbuffer_channels(const std::string& layer) {
  if (layer == "motion") return {"motion.X", "motion.Y"};
  if (layer == "depth") return {"depth.Z"};
  return {layer};
}

}  // namespace temporal
