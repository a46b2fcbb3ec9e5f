// The glTF 2.0 reader: tinygltf parses the file, the Loader converts the model into the format-neutral
// SceneDescription (scene_description.h). gltf_load.cpp: nodes, skins, animations, cameras, lights, draws;
// gltf_mesh.cpp: textures, materials, meshes. Internal to src/scene.
#pragma once

#include "gltf_accessor.h"
#include "scene_description.h"

#include <glm/mat3x3.hpp>

#include <map>
#include <string>
#include <vector>

namespace temporal::scene_detail {

// Fills `out` from the glTF file at `path` (.gltf JSON or .glb, told apart by the magic bytes).
Status read_gltf(const std::string& path, const SceneLoadOptions& options, SceneDescription& out);

// Converts one parsed tinygltf::Model into a SceneDescription; each step validates what it reads.
struct Loader {
  const tinygltf::Model& model;
  const std::string& file;
  SceneDescription& out;
  std::vector<int> node_mesh, node_camera, node_light;  // glTF node -> mesh / camera / light (-1: none)
  std::vector<char> in_scene;                           // glTF node -> drawn by the selected scene
  std::map<int, int> texture_map;                 // glTF texture -> textures index
  std::vector<std::vector<int>> mesh_primitives;  // glTF mesh -> primitives indices (-1: skipped)
  std::vector<int> mesh_targets;                  // glTF mesh -> morph target count
  std::vector<std::uint32_t> max_joint;           // per loaded primitive: largest JOINTS_n value + 1
  std::vector<glm::mat3> uv_transform;            // per material: KHR_texture_transform of the base colour texture
  int default_material = -1;

  Status load_texture(int gltf_texture, int* out_index);
  Status load_materials();
  Status load_meshes();
  Status load_mesh(int mesh_index, bool skinned_use);
  Status load_nodes_and_order();
  Status load_skins();
  Status build_draws();
  Status load_animations(const std::string& clip);
  Status load_cameras_and_lights();

 private:
  Status load_node(std::size_t index);
  void mark_drawn_scene();
  Status select_clips(const std::string& clip, std::vector<std::size_t>& selected);
  Status load_channel(std::size_t animation, std::size_t channel, std::map<int, int>& sampler_map,
                      std::vector<char>& animated);
  Status load_primitive(const tinygltf::Primitive& prim, const std::string& what, bool skinned_use, int* index);
};

}  // namespace temporal::scene_detail
