// Animated scenes (glTF 2.0 and text USD), evaluated on the CPU at any time t.
//
// A Scene is loaded once and validated: Scene::load recognises the format by the file's content (a glTF
// JSON document or .glb magic, or a `#usda 1.0` text layer; binary USD crate files are refused with a
// message saying how to convert them), and each reader fills one format-neutral description
// (docs/scenes.md, docs/usd.md). evaluate(t) returns everything a rasteriser needs for that instant: one
// PrimitiveInstance per drawn primitive (in the same order at every t, so two evaluations can be paired index
// by index for motion vectors), the camera and the lights. Only what a primitive needs is computed: rigid
// primitives carry a model matrix and share their rest-pose vertex buffers; only skinned, morphed or
// point-cached primitives get deformed world-space vertices (CPU linear blend skinning and morph targets /
// blend shapes).
#pragma once

#include "temporal/core/error.h"
#include "temporal/core/sequence.h"

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace temporal {

struct SceneTexture {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgba8;  // row 0 is the top row of the image (glTF UV v = 0 is the top; USD
                                    // readers flip st.t so that the same convention holds)
  bool srgb = true;                 // base colour textures are sRGB-encoded (USD: unless sourceColorSpace "raw")
  bool repeat_s = true, repeat_t = true;
  bool mirror_s = false, mirror_t = false;
  bool nearest = false;             // magnification filter NEAREST
  bool mipmaps = true;              // minification filter uses mipmaps (or is unset); false for NEAREST/LINEAR
};

struct SceneMaterial {
  std::string name;
  glm::vec4 base_color_factor{1.0f};
  int base_color_texture = -1;      // index into Scene::textures(), -1: none
  int base_color_texcoord = 0;
  float metallic = 0.0f;
  float roughness = 1.0f;
  glm::vec3 emissive{0.0f};
  enum class AlphaMode { Opaque, Mask, Blend } alpha_mode = AlphaMode::Opaque;
  float alpha_cutoff = 0.5f;
  bool double_sided = false;
};

// Rest-pose geometry of one drawn primitive (triangles only: glTF strips and fans and USD polygons are
// triangulated on load).
struct ScenePrimitive {
  std::vector<glm::vec3> positions;  // object space
  std::vector<glm::vec3> normals;    // object space; generated (flat) when the file has none
  std::vector<glm::vec2> texcoords;  // TEXCOORD_n of the material's base colour texture (normally TEXCOORD_0;
                                     // USD: primvars:st with t flipped to 1 - t), empty when absent
  std::vector<std::uint32_t> indices;
  int material = -1;                 // index into Scene::materials(); after load never -1: primitives without
                                     // a material get a "default" one appended to Scene::materials()
  bool skinned = false;              // has joint influences (JOINTS_0/WEIGHTS_0, UsdSkel) and a skin
  bool morphed = false;              // has morph targets (glTF) or blend shapes (UsdSkel)
};

// One drawn primitive at one instant.
struct PrimitiveInstance {
  int primitive = -1;                // index into Scene::primitives()
  int node = -1;                     // node that draws it (glTF: the node index; USD: in prim traversal order)
  std::uint32_t id = 0;              // material id + 1 (0 is the background, docs/conventions.md)
  glm::mat4 model{1.0f};             // object to world (rigid primitives)
  bool deformed = false;             // true: use the world-space vertices below instead of model
  std::vector<glm::vec3> world_positions;  // deformed only, world space
  std::vector<glm::vec3> world_normals;    // deformed only, world space, normalised
};

// The narrowest vertical field of view a camera may have (radians): below it 1 / tan(yfov / 2) overflows float
// and every projected position is NaN. Loaders refuse such cameras; render-gbuffer checks every frame's camera.
inline constexpr float kMinCameraYfov = 1e-4f;

struct CameraState {
  glm::mat4 view{1.0f};              // world to camera (OpenGL: looks down -Z)
  float yfov = 0.8f;                 // radians
  float aspect = 0.0f;               // 0: use the image's aspect
  float znear = 0.1f;
  float zfar = 100.0f;
  std::string name;
};

struct LightState {
  enum class Type { Directional, Point, Spot } type = Type::Directional;
  glm::vec3 position{0.0f};          // world space (point, spot)
  glm::vec3 direction{0.0f, -1.0f, 0.0f};  // world space, direction the light travels (directional, spot)
  glm::vec3 color{1.0f};
  float intensity = 1.0f;            // KHR_lights_punctual units (lux for directional, candela otherwise;
                                     // docs/usd.md gives the UsdLux conversion)
  float range = 0.0f;                // 0: infinite
  float inner_cone = 0.0f, outer_cone = 0.785398f;
};

struct FrameState {
  double time = 0.0;
  std::vector<PrimitiveInstance> instances;
  CameraState camera;
  std::vector<LightState> lights;    // never empty: an automatic key light when the scene has none (directional,
                                     // white, intensity pi, from above and behind the camera's left at t = 0)
  glm::vec3 ambient{0.0f};           // radiance of a uniform environment light (USD DomeLight), 0 for glTF
};

// How the camera is chosen and moved.
struct CameraOptions {
  std::string camera;                // camera name or index (USD: prim name or path); empty: the first
                                     // perspective camera, or an automatic one. Orthographic cameras are
                                     // refused (Usage error) and skipped when choosing the first camera.
  enum class Path { Fixed, Orbit, Dolly } path = Path::Fixed;  // a path forces the automatic camera
  double path_period_s = 8.0;        // orbit: seconds per turn; dolly: seconds per back-and-forth (> 0)
  // The automatic camera frames the bounding sphere at t = 0 (yfov 0.8 rad) from direction (0.45, 0.35, 1)
  // of its centre; orbit turns it about the vertical axis through the centre, dolly moves it along its view
  // direction between 100 % and 65 % of the framing distance (cosine ease).
};

// "fixed", "orbit", "dolly" (render-gbuffer --camera-path).
Expected<CameraOptions::Path> parse_camera_path(const std::string& text);
const char* camera_path_name(CameraOptions::Path path);

struct SceneLoadOptions {
  std::string clip;                  // glTF animation name or index; empty: the first animation (if any);
                                     // "all": every animation of the file at once. USD scenes have one
                                     // timeline: only empty or "all" are accepted.
  CameraOptions camera;
};

class Scene {
 public:
  // Loads a glTF 2.0 (.gltf, .glb) or text USD (.usda, or .usd holding text) scene, recognised by its
  // content. Errors (Input) name the file and what is wrong: malformed JSON, missing buffer or image,
  // accessor out of range, unsupported required extension (named), `file:line:column: ...` for malformed
  // USD text, an unresolvable USD reference, a crate (.usdc/.usdz) file, no triangles to draw.
  static Expected<Scene> load(const std::string& path, const SceneLoadOptions& options = {});

  const std::vector<ScenePrimitive>& primitives() const;
  const std::vector<SceneMaterial>& materials() const;
  const std::vector<SceneTexture>& textures() const;
  // Axis-aligned bounds of the scene in its rest pose at t = 0, world space.
  glm::vec3 bounds_min() const;
  glm::vec3 bounds_max() const;
  // Duration of the selected animation clip in seconds (0 when static). USD: the stage's timeline,
  // (endTimeCode - startTimeCode) / timeCodesPerSecond + 1 / framesPerSecond (the last frame is held for
  // one frame), 0 when nothing is time-sampled.
  double clip_duration() const;
  std::vector<std::string> clip_names() const;
  std::vector<std::string> camera_names() const;
  // "glTF 2.0" or "USD".
  const std::string& format() const;
  // Radiance of a uniform environment light (USD DomeLight: intensity * 2^exposure * color); 0 for glTF.
  glm::vec3 ambient() const;

  // The frames render-gbuffer replays when no --frames are given: 0 .. ceil(S * fps) - 1 for S =
  // duration_s when positive, else the clip's duration, else one camera-path period when a path is set;
  // a static scene gives frame 0 only.
  FrameRange default_frames(double fps, double duration_s = 0.0) const;

  // The scene at time t (seconds; animation time wraps at the clip's end, so sequences can run longer).
  // Thread-safe: const and allocation-local.
  FrameState evaluate(double time_s) const;
  // The same, reusing `out`'s storage (instances and deformed vertex arrays keep their capacity; the
  // per-call scratch is a few matrices per node): for per-frame loops.
  void evaluate(double time_s, FrameState& out) const;

  // Every file the load read: the scene file first, then glTF buffers and images or USD layers and textures
  // (render-gbuffer refuses to write over any of them).
  const std::vector<std::string>& input_files() const;
  // The scene file as given to load().
  const std::string& file() const;

  // What the loader skipped or changed (points/lines primitives, ignored channels, ...), one line each.
  const std::vector<std::string>& warnings() const;

  Scene();
  Scene(Scene&&) noexcept;
  Scene& operator=(Scene&&) noexcept;
  ~Scene();

 private:
  static Expected<Scene> load_checked(const std::string& path, const SceneLoadOptions& options);
  Status finish(const SceneLoadOptions& options);  // bounds, camera and key light (scene_finish.cpp)
  struct Impl;  // the format-neutral description and evaluation state: src/scene/scene_description.h
  std::unique_ptr<Impl> impl_;
};

}  // namespace temporal
