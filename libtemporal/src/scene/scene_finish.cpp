// The format-neutral end of Scene::load: once a reader has filled the description, compute the bounds at
// t = 0, choose the camera (named, first perspective, or automatic) and add the key light when the scene has
// none. The same rules hold for every format (docs/scenes.md "Choices").
#include "scene_description.h"

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>

namespace temporal {
namespace {

using scene_detail::Impl;
using scene_detail::is_index;
using scene_detail::join_names;


// The camera definition `wanted` names (name, USD path or index; the last of several equal names wins), or -1.
int find_camera(const Impl& impl, const std::string& wanted) {
  int index = -1;
  for (std::size_t i = 0; i < impl.cameras.size(); ++i) {
    if (impl.cameras[i].name == wanted || (!impl.cameras[i].path.empty() && impl.cameras[i].path == wanted)) {
      index = static_cast<int>(i);
    }
  }
  if (index < 0 && is_index(wanted) && std::stoul(wanted) < impl.cameras.size()) index = std::stoi(wanted);
  return index;
}

}  // namespace

// Bounds at t = 0 (skinned and morphed meshes in their pose at t = 0).
static void compute_bounds(const Scene& scene, Impl& impl) {
  FrameState f0;
  scene.evaluate(0.0, f0);
  glm::vec3 lo(std::numeric_limits<float>::max()), hi(std::numeric_limits<float>::lowest());
  for (const PrimitiveInstance& inst : f0.instances) {
    if (inst.deformed) {
      for (const auto& p : inst.world_positions) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
      }
      continue;
    }
    const scene_detail::PrimitiveData& d = impl.primitive_data[static_cast<std::size_t>(inst.primitive)];
    for (int c = 0; c < 8; ++c) {
      const glm::vec3 corner((c & 1) ? d.local_max.x : d.local_min.x, (c & 2) ? d.local_max.y : d.local_min.y,
                             (c & 4) ? d.local_max.z : d.local_min.z);
      const glm::vec3 w = glm::vec3(inst.model * glm::vec4(corner, 1.0f));
      lo = glm::min(lo, w);
      hi = glm::max(hi, w);
    }
  }
  impl.bounds_min = lo;
  impl.bounds_max = hi;
}

Status Scene::finish(const SceneLoadOptions& options) {
  Impl& impl = *impl_;
  const std::string& path = impl.file;
  if (impl.draws.empty()) return Error::input(path, "the scene has no triangles to draw");
  // Vertex data that is not finite would put NaN into every output that sees the surface (albedo, colour,
  // payload, reference): a malformed scene, refused whichever format it came from.
  for (std::size_t i = 0; i < impl.primitives.size(); ++i) {
    const ScenePrimitive& p = impl.primitives[i];
    auto finite3 = [](const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); };
    auto finite2 = [](const glm::vec2& v) { return scene_detail::texcoord_in_range(v); };  // false for NaN, inf
    const char* bad = !std::all_of(p.positions.begin(), p.positions.end(), finite3)   ? "positions"
                      : !std::all_of(p.normals.begin(), p.normals.end(), finite3)     ? "normals"
                      : !std::all_of(p.texcoords.begin(), p.texcoords.end(), finite2) ? "texture coordinates (or beyond +-1e6)"
                                                                                      : nullptr;
    if (bad)
      return Error::input(path, "primitive " + std::to_string(i) + " has " + bad + " that hold NaN or infinite values: "
                                    "the file is malformed; re-export it");
  }
  compute_bounds(*this, impl);
  const glm::vec3 center = 0.5f * (impl.bounds_min + impl.bounds_max);
  const float radius = std::max(0.5f * glm::length(impl.bounds_max - impl.bounds_min), 1e-3f);

  // Camera: the named / first perspective camera through its node, or the automatic one.
  const CameraOptions& co = options.camera;
  impl.path = co.path;
  impl.path_period_s = co.path_period_s > 0.0 ? co.path_period_s : 8.0;
  int camera_index = -1;
  if (!co.camera.empty()) {
    camera_index = find_camera(impl, co.camera);
    if (camera_index < 0) {
      return Error{ErrorKind::Usage, path, "no camera '" + co.camera + "' (have: " + join_names(camera_names()) +
                                               "); give a name or an index, or omit it for the automatic camera"};
    }
    if (impl.cameras[static_cast<std::size_t>(camera_index)].orthographic) {
      return Error{ErrorKind::Usage, path, "camera '" + co.camera + "' is orthographic, which is not supported (only "
                                               "perspective cameras); choose another camera or the automatic one"};
    }
  }
  if (co.path == CameraOptions::Path::Fixed) {
    for (std::size_t i = 0; i < impl.camera_instances.size(); ++i) {
      const int c = impl.camera_instances[i].camera;
      if (camera_index >= 0 ? c == camera_index : !impl.cameras[static_cast<std::size_t>(c)].orthographic) {
        impl.camera_instance = static_cast<int>(i);
        impl.camera = impl.cameras[static_cast<std::size_t>(c)];
        break;
      }
    }
    if (camera_index >= 0 && impl.camera_instance < 0) {
      return Error{ErrorKind::Usage, path, "camera '" + co.camera + "' is not attached to any node of the scene"};
    }
  }
  // Automatic camera: frames the bounding sphere from the front (+Z), a little from the right and above.
  impl.auto_center = center;
  impl.auto_direction = glm::normalize(glm::vec3(0.45f, 0.35f, 1.0f));
  const float auto_yfov = CameraState{}.yfov;
  impl.auto_distance = radius / std::sin(0.5f * auto_yfov) * 1.05f;
  if (impl.camera_instance >= 0 && impl.camera.zfar == 0.0f && impl.camera.clipping_sampler < 0) {
    // Infinite projection in the file: a far plane beyond the whole scene as seen from the camera at t = 0.
    const glm::vec3 eye(glm::inverse(evaluate(0.0).camera.view)[3]);
    impl.camera.zfar = std::max(2.0f * (glm::length(eye - center) + radius), 2.0f * impl.camera.znear);
  }
  // Key light when the scene has none: a white directional light from above, behind the camera's left
  // shoulder at t = 0; intensity pi, so a white Lambertian surface facing it reflects radiance 1.
  if (impl.lights.empty()) {
    const glm::mat4 cam_to_world = glm::inverse(evaluate(0.0).camera.view);
    const glm::vec3 right(cam_to_world[0]), up(cam_to_world[1]), back(cam_to_world[2]);
    impl.key_light.type = LightState::Type::Directional;
    impl.key_light.direction = glm::normalize(-back * 1.0f - up * 1.2f + right * 0.6f);
    impl.key_light.color = glm::vec3(1.0f);
    impl.key_light.intensity = 3.14159265f;
  }
  return Status::ok();
}

}  // namespace temporal
