// The glTF-to-Scene conversion state shared by scene_load.cpp (nodes, skins, animations, cameras, lights,
// Scene::load) and mesh_load.cpp (textures, materials, meshes). Internal to src/scene.
#pragma once

#include "accessor.h"
#include "scene_impl.h"

#include <glm/mat3x3.hpp>

#include <map>
#include <string>
#include <vector>

namespace temporal::scene_detail {

// "'name'" or "#index" for messages.
std::string quoted_or_index(const std::string& name, std::size_t index);

// Converts one parsed tinygltf::Model into a Scene's arrays; each step validates what it reads.
struct Loader {
  const tinygltf::Model& model;
  const std::string& file;
  Impl& impl;
  std::vector<ScenePrimitive>& primitives;
  std::vector<SceneMaterial>& materials;
  std::vector<SceneTexture>& textures;
  std::map<int, int> texture_map;  // glTF texture -> textures index
  std::vector<std::vector<int>> mesh_primitives;  // glTF mesh -> primitives indices (-1: skipped)
  std::vector<int> mesh_targets;                  // glTF mesh -> morph target count
  std::vector<std::uint32_t> max_joint;           // per loaded primitive: largest JOINTS_n value + 1
  std::vector<glm::mat3> uv_transform;            // per material: KHR_texture_transform of the base colour texture
  int default_material = -1;

  Status load_texture(int gltf_texture, int* out_index);
  Status load_materials();
  Status load_mesh(int mesh_index, bool skinned_use);
  Status load_nodes_and_order(std::vector<char>& in_scene);
  Status load_skins();
  Status load_animations(const std::string& clip, double& duration);
  Status load_cameras_and_lights(const std::vector<char>& in_scene);
};


}  // namespace temporal::scene_detail
