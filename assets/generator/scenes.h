// The built-in scenes (docs/scenes.md says which seed situation each one covers).
#pragma once

#include "gltf_builder.h"

#include <functional>
#include <string>
#include <vector>

namespace scenegen {

struct SceneRecipe {
  std::string name;         // file name without .glb
  std::string description;  // one line
  std::function<void(GltfBuilder&)> build;
};

// All built-in scenes, the demo default first.
const std::vector<SceneRecipe>& recipes();

void build_walkers(GltfBuilder& b);     // skinned quadrupeds trotting round a yard, static camera (seed 000 horses)
void build_tower(GltfBuilder& b);       // camera circling a tower behind two rings of columns (seed 004 Tower)
void build_fan(GltfBuilder& b);         // spinning fans before a brick wall (seed 004 Fan)
void build_fence(GltfBuilder& b);       // fences, railings, fine checker, cut-out foliage (seed 003 flicker)
void build_morph_test(GltfBuilder& b);  // a waving flag of two morph targets (tests)

}  // namespace scenegen
