// The built-in scenes. Units are metres and seconds, Y up, as in glTF. Every scene has a ground plane
// with a procedural texture, its own perspective camera and KHR_lights_punctual lights, and one clip.
#include "scenes.h"

#include "shapes.h"

#include <glm/gtc/matrix_transform.hpp>

#include <cmath>

namespace scenegen {
namespace {

constexpr float kPi = 3.14159265358979f;
constexpr float kTwoPi = 2.0f * kPi;

glm::mat4 translate(float x, float y, float z) { return glm::translate(glm::mat4(1.0f), glm::vec3(x, y, z)); }
glm::mat4 rotate_x(float a) { return glm::rotate(glm::mat4(1.0f), a, glm::vec3(1, 0, 0)); }
glm::mat4 rotate_y(float a) { return glm::rotate(glm::mat4(1.0f), a, glm::vec3(0, 1, 0)); }
glm::mat4 rotate_z(float a) { return glm::rotate(glm::mat4(1.0f), a, glm::vec3(0, 0, 1)); }
glm::quat quat_axis(float a, glm::vec3 axis) { return glm::angleAxis(a, glm::normalize(axis)); }
float deg(float d) { return d * kPi / 180.0f; }

// n + 1 key times evenly over [0, duration].
std::vector<float> key_times(int n, float duration) {
  std::vector<float> t;
  for (int k = 0; k <= n; ++k) t.push_back(duration * static_cast<float>(k) / static_cast<float>(n));
  return t;
}

// One CUBICSPLINE key of a translation (glTF Appendix C): in-tangent, value, out-tangent, for a point p moving at v.
void push_hermite_key(std::vector<float>& values, const glm::vec3& p, const glm::vec3& v) {
  values.insert(values.end(), {v.x, v.y, v.z, p.x, p.y, p.z, v.x, v.y, v.z});
}

// The rotation keys of a flying camera at `times`: looking from position(t) at target(t).
template <typename Position, typename Target>
void animate_look_at(GltfBuilder& b, int cam, const std::vector<float>& times, Position&& position, Target&& target) {
  std::vector<float> values;
  for (float t : times) push_quat(values, look_rotation(target(t) - position(t)));
  b.animate(cam, "rotation", times, values);
}

void scale_uv(MeshData& m, float su, float sv) {
  for (auto& uv : m.texcoords) uv *= glm::vec2(su, sv);
}

int add_ground(GltfBuilder& b, float size, int tex_size, int squares, float repeat, glm::vec3 a, glm::vec3 c, int subdiv) {
  const int tex = b.add_texture(checker("ground_checker", tex_size, squares, a, c));
  MaterialDesc m;
  m.name = "ground";
  m.texture = tex;
  m.roughness = 0.9f;
  const int mat = b.add_material(m);
  const int node = b.add_node("ground");
  b.set_mesh(node, b.add_mesh("ground", plane(size, repeat, subdiv), mat));
  return node;
}

void add_static_camera(GltfBuilder& b, const std::string& name, glm::vec3 eye, glm::vec3 target, float yfov, float znear,
                       float zfar) {
  const int node = b.add_node(name, -1, eye, look_rotation(target - eye));
  b.set_camera(node, name, yfov, znear, zfar);
}

void add_sun(GltfBuilder& b, glm::vec3 direction, float lux, glm::vec3 color) {
  const int node = b.add_node("sun", -1, glm::vec3(0.0f, 20.0f, 0.0f), look_rotation(direction, glm::vec3(0, 0, 1)));
  LightDesc l;
  l.name = "sun";
  l.type = "directional";
  l.intensity = lux;
  l.color = color;
  b.set_light(node, l);
}

void add_point(GltfBuilder& b, const std::string& name, glm::vec3 pos, float candela, glm::vec3 color, float range = 0.0f) {
  const int node = b.add_node(name, -1, pos);
  LightDesc l;
  l.name = name;
  l.type = "point";
  l.intensity = candela;
  l.color = color;
  l.range = range;
  b.set_light(node, l);
}

int simple_material(GltfBuilder& b, const std::string& name, glm::vec3 color, float roughness = 0.7f, int texture = -1,
                    float metallic = 0.0f) {
  MaterialDesc m;
  m.name = name;
  m.base_color = glm::vec4(color, 1.0f);
  m.roughness = roughness;
  m.metallic = metallic;
  m.texture = texture;
  return b.add_material(m);
}

void static_mesh(GltfBuilder& b, const std::string& name, const MeshData& mesh, int material, glm::vec3 pos = glm::vec3(0.0f),
                 glm::quat rot = glm::quat(1, 0, 0, 0)) {
  const int node = b.add_node(name, -1, pos, rot);
  b.set_mesh(node, b.add_mesh(name, mesh, material));
}

// ---------------------------------------------------------------- walkers (seed 000, horses)

// Skeleton of the quadruped, in its own space (facing +X, feet at y = 0). Joint order of the skin.
enum Joint { kBody, kNeck, kHead, kTail, kUpper0, kLower0 };  // legs: kUpper0 + 2 * leg, kLower0 + 2 * leg
constexpr int kJoints = 12;
const glm::vec3 kLegXZ[4] = {{0.6f, 0, 0.17f}, {0.6f, 0, -0.17f}, {-0.6f, 0, 0.17f}, {-0.6f, 0, -0.17f}};  // FL FR HL HR
constexpr float kHip = 1.05f, kKnee = 0.55f;

glm::vec3 joint_pivot(int j) {
  switch (j) {
    case kBody: return {0.0f, 1.3f, 0.0f};
    case kNeck: return {0.75f, 1.45f, 0.0f};
    case kHead: return {1.05f, 1.95f, 0.0f};
    case kTail: return {-0.82f, 1.5f, 0.0f};
    default: {
      const int leg = (j - kUpper0) / 2;
      const bool lower = (j - kUpper0) % 2 == 1;
      return kLegXZ[leg] + glm::vec3(0.0f, lower ? kKnee : kHip, 0.0f);
    }
  }
}
int joint_parent(int j) {
  if (j == kBody) return -1;
  if (j == kHead) return kNeck;
  if (j >= kUpper0 && (j - kUpper0) % 2 == 1) return j - 1;
  return kBody;
}

MeshData quadruped_mesh() {
  MeshData m;
  auto part = [&](MeshData piece, const glm::mat4& xf, int joint) {
    piece.bind_all(joint);
    m.append(piece, xf);
  };
  part(box({1.7f, 0.55f, 0.5f}, 2), translate(0.0f, 1.3f, 0.0f), kBody);
  part(box({0.22f, 0.75f, 0.26f}), translate(0.88f, 1.72f, 0.0f) * rotate_z(deg(-35.0f)), kNeck);
  part(box({0.55f, 0.22f, 0.22f}), translate(1.2f, 2.0f, 0.0f) * rotate_z(deg(-20.0f)), kHead);
  part(box({0.08f, 0.55f, 0.08f}), translate(-0.95f, 1.3f, 0.0f) * rotate_z(deg(20.0f)), kTail);
  for (int leg = 0; leg < 4; ++leg) {
    // One box from the hoof to the hip, split in 6 rings; the rings around the knee blend the two joints.
    MeshData piece = box({0.14f, kHip, 0.14f}, 6);
    piece.joints.resize(piece.positions.size());
    piece.weights.resize(piece.positions.size());
    for (std::size_t v = 0; v < piece.positions.size(); ++v) {
      const float y = piece.positions[v].y + 0.5f * kHip;  // 0 at the hoof
      const float lower = std::clamp((0.75f - y) / 0.35f, 0.0f, 1.0f);
      piece.joints[v] = glm::u16vec4(kUpper0 + 2 * leg, kLower0 + 2 * leg, 0, 0);
      piece.weights[v] = glm::vec4(1.0f - lower, lower, 0.0f, 0.0f);
    }
    m.append(piece, translate(kLegXZ[leg].x, 0.5f * kHip, kLegXZ[leg].z));
  }
  return m;
}

// One quadruped trotting round a circle of `radius` (one lap per clip), `direction` +1 counter-clockwise
// seen from above, gait phase offset `phase`.
void add_walker(GltfBuilder& b, const std::string& name, int mesh, float radius, float direction, float phase,
                float clip_s) {
  // Carousel: a node at the centre turning once per clip; the animal sits on it at (radius, 0, 0).
  const int carousel = b.add_node(name + "_carousel");
  std::vector<float> times = key_times(16, clip_s), values;  // 22.5 degree steps: slerp is exact
  for (float t : times) push_quat(values, quat_axis(direction * kTwoPi * t / clip_s, {0, 1, 0}));
  b.animate(carousel, "rotation", times, values);
  const int root = b.add_node(name, carousel, glm::vec3(radius, 0.0f, 0.0f), quat_axis(direction * kPi / 2, {0, 1, 0}));

  std::vector<int> nodes(kJoints);
  for (int j = 0; j < kJoints; ++j) {
    const int parent = joint_parent(j);
    const glm::vec3 local = joint_pivot(j) - (parent >= 0 ? joint_pivot(parent) : glm::vec3(0.0f));
    nodes[static_cast<std::size_t>(j)] = b.add_node(name + "_joint" + std::to_string(j),
                                                     parent >= 0 ? nodes[static_cast<std::size_t>(parent)] : root, local);
  }
  std::vector<glm::mat4> inverse_bind;
  for (int j = 0; j < kJoints; ++j) inverse_bind.push_back(glm::translate(glm::mat4(1.0f), -joint_pivot(j)));
  const int skinned = b.add_node(name + "_mesh", root);
  b.set_mesh(skinned, mesh);
  b.set_skin(skinned, nodes, inverse_bind, root);

  // Trot: 2 strides per second, 16 keys per stride, diagonal legs in phase.
  const float stride_s = 0.5f;
  const int keys = static_cast<int>(std::lround(clip_s / stride_s)) * 16;
  times = key_times(keys, clip_s);
  const float leg_phase[4] = {0.0f, kPi, kPi, 0.0f};
  auto phi = [&](float t) { return kTwoPi * t / stride_s + phase; };
  auto channel = [&](int joint, const std::function<glm::quat(float)>& f) {
    std::vector<float> v;
    for (float t : times) push_quat(v, f(phi(t)));
    b.animate(nodes[static_cast<std::size_t>(joint)], "rotation", times, v);
  };
  std::vector<float> bob;
  for (float t : times) {
    const glm::vec3 p = joint_pivot(kBody) + glm::vec3(0.0f, 0.05f * std::sin(2.0f * phi(t)), 0.0f);
    bob.insert(bob.end(), {p.x, p.y, p.z});
  }
  b.animate(nodes[kBody], "translation", times, bob);
  channel(kBody, [](float p) { return quat_axis(deg(3.0f) * std::sin(p), {0, 0, 1}); });
  channel(kNeck, [](float p) { return quat_axis(deg(6.0f) * std::sin(2.0f * p), {0, 0, 1}); });
  channel(kHead, [](float p) { return quat_axis(deg(-6.0f) * std::sin(2.0f * p + 0.5f), {0, 0, 1}); });
  channel(kTail, [](float p) { return quat_axis(deg(15.0f) * std::sin(p), {1, 0, 0}) * quat_axis(deg(10.0f), {0, 0, 1}); });
  for (int leg = 0; leg < 4; ++leg) {
    const float lp = leg_phase[leg];
    // Positive rotation about Z swings the hoof forward (+X).
    channel(kUpper0 + 2 * leg, [lp](float p) { return quat_axis(deg(28.0f) * std::sin(p + lp), {0, 0, 1}); });
    // The lower leg folds back while the leg swings forward.
    channel(kLower0 + 2 * leg, [lp](float p) {
      return quat_axis(-deg(5.0f) - deg(50.0f) * std::max(0.0f, std::cos(p + lp)), {0, 0, 1});
    });
  }
}

}  // namespace

void build_walkers(GltfBuilder& b) {
  const float clip = 4.0f;
  b.set_clip_name("trot");
  add_ground(b, 24.0f, 256, 8, 6.0f, {0.55f, 0.50f, 0.42f}, {0.36f, 0.33f, 0.28f}, 8);
  // Props for contact shadows and ambient occlusion: a trough in the middle, crates and a wall behind.
  const int wood = simple_material(b, "wood", {0.45f, 0.30f, 0.18f}, 0.8f);
  const int stone = simple_material(b, "stone", {0.8f, 0.8f, 0.78f}, 0.9f,
                                    b.add_texture(bricks("wall_bricks", 128, 8, {0.62f, 0.36f, 0.27f}, {0.75f, 0.73f, 0.7f})));
  static_mesh(b, "trough", box({1.6f, 0.7f, 0.8f}), wood, {0.0f, 0.35f, 0.0f}, quat_axis(deg(25.0f), {0, 1, 0}));
  for (int k = 0; k < 4; ++k) {
    const float a = deg(40.0f + 95.0f * static_cast<float>(k));
    static_mesh(b, "crate" + std::to_string(k), box({1.0f, 1.0f, 1.0f}), wood,
                {7.8f * std::cos(a), 0.5f, -7.8f * std::sin(a)}, quat_axis(a, {0, 1, 0}));
  }
  MeshData wall = box({16.0f, 2.2f, 0.4f});
  scale_uv(wall, 6.0f, 1.0f);
  static_mesh(b, "wall", wall, stone, {0.0f, 1.1f, -9.5f});

  const int coat_a = simple_material(b, "coat_bay", {0.42f, 0.24f, 0.12f}, 0.6f);
  const int coat_b = simple_material(b, "coat_grey", {0.78f, 0.76f, 0.72f}, 0.6f);
  const MeshData body = quadruped_mesh();
  add_walker(b, "walker_a", b.add_mesh("quadruped_bay", body, coat_a), 3.3f, 1.0f, 0.0f, clip);
  add_walker(b, "walker_b", b.add_mesh("quadruped_grey", body, coat_b), 5.6f, -1.0f, 1.3f, clip);

  add_static_camera(b, "overview", {0.0f, 5.2f, 12.0f}, {0.0f, 0.4f, -0.6f}, 0.80f, 0.5f, 60.0f);
  add_sun(b, {-0.5f, -1.0f, -0.35f}, 3.0f, {1.0f, 0.96f, 0.9f});
  add_point(b, "fill", {-4.0f, 4.0f, 5.0f}, 40.0f, {0.7f, 0.8f, 1.0f});
}

// ---------------------------------------------------------------- tower (seed 004, Tower)

void build_tower(GltfBuilder& b) {
  const float clip = 12.0f;
  b.set_clip_name("flyaround");
  add_ground(b, 70.0f, 256, 4, 24.0f, {0.50f, 0.50f, 0.48f}, {0.38f, 0.38f, 0.37f}, 10);
  const int brick_tex = b.add_texture(bricks("tower_bricks", 256, 16, {0.70f, 0.62f, 0.50f}, {0.85f, 0.83f, 0.80f}));
  const int masonry = simple_material(b, "masonry", {1.0f, 1.0f, 1.0f}, 0.85f, brick_tex);
  const int marble = simple_material(b, "marble", {0.85f, 0.84f, 0.80f}, 0.35f);
  const int roof = simple_material(b, "roof", {0.45f, 0.12f, 0.10f}, 0.6f);

  // The tower: a brick cylinder, a parapet of merlons and a conical roof.
  MeshData tower = cylinder(2.2f, 12.0f, 24);
  scale_uv(tower, 6.0f, 5.0f);
  static_mesh(b, "tower", tower, masonry);
  MeshData merlons;
  for (int k = 0; k < 16; ++k) {
    const float a = kTwoPi * static_cast<float>(k) / 16.0f;
    merlons.append(box({0.5f, 0.6f, 0.5f}), translate(2.2f * std::sin(a), 12.3f, 2.2f * std::cos(a)) * rotate_y(a));
  }
  static_mesh(b, "merlons", merlons, masonry);
  MeshData cap = cone(2.0f, 3.2f, 24);
  static_mesh(b, "roof", cap, roof, {0.0f, 12.0f, 0.0f});

  // Inner colonnade (radius 5, with lintels) and outer ring of free columns (radius 8.5).
  MeshData colonnade;
  const int inner = 10;
  for (int k = 0; k < inner; ++k) {
    const float a = kTwoPi * static_cast<float>(k) / inner;
    const glm::mat4 at = translate(5.0f * std::sin(a), 0.0f, 5.0f * std::cos(a)) * rotate_y(a);
    colonnade.append(box({0.9f, 0.3f, 0.9f}), at * translate(0, 0.15f, 0));
    colonnade.append(cylinder(0.33f, 4.5f, 12, false), at * translate(0, 0.3f, 0));
    colonnade.append(box({0.9f, 0.25f, 0.9f}), at * translate(0, 4.925f, 0));
    // Lintel to the next column: a beam along the chord.
    const float a2 = kTwoPi * static_cast<float>(k + 1) / inner;
    const glm::vec3 p0(5.0f * std::sin(a), 0, 5.0f * std::cos(a)), p1(5.0f * std::sin(a2), 0, 5.0f * std::cos(a2));
    const glm::vec3 mid = 0.5f * (p0 + p1);
    const float len = glm::length(p1 - p0);
    colonnade.append(box({len, 0.4f, 0.6f}), translate(mid.x, 5.25f, mid.z) * rotate_y(0.5f * (a + a2) + kPi / 2));
  }
  const int outer = 14;
  for (int k = 0; k < outer; ++k) {
    const float a = kTwoPi * (static_cast<float>(k) + 0.5f) / outer;
    const glm::mat4 at = translate(8.5f * std::sin(a), 0.0f, 8.5f * std::cos(a)) * rotate_y(a);
    const float h = 2.8f + 1.2f * hash01(static_cast<std::uint32_t>(k), 11u);
    colonnade.append(box({0.8f, 0.3f, 0.8f}), at * translate(0, 0.15f, 0));
    colonnade.append(cylinder(0.3f, h, 12), at * translate(0, 0.3f, 0));
  }
  static_mesh(b, "columns", colonnade, marble);

  // Camera: one lap at radius 11.5 in 12 s between the outer columns, bobbing in height, aiming at the
  // tower at a height that drifts. Position: CUBICSPLINE keys every second with the analytic velocity as
  // tangents; orientation: LINEAR keys every 0.1 s (the look-at direction).
  const float radius = 11.5f;
  auto position = [&](float t) {
    const float th = kTwoPi * t / clip;
    return glm::vec3(radius * std::sin(th), 2.2f + 0.8f * std::sin(2.0f * th), radius * std::cos(th));
  };
  auto velocity = [&](float t) {
    const float th = kTwoPi * t / clip, w = kTwoPi / clip;
    return w * glm::vec3(radius * std::cos(th), 1.6f * std::cos(2.0f * th), -radius * std::sin(th));
  };
  auto target = [&](float t) { return glm::vec3(0.0f, 3.5f + 1.5f * std::sin(kTwoPi * t / clip), 0.0f); };
  const int cam = b.add_node("flyaround_camera", -1, position(0.0f), look_rotation(target(0.0f) - position(0.0f)));
  b.set_camera(cam, "flyaround", 0.9f, 0.3f, 120.0f);
  const std::vector<float> times = key_times(12, clip);
  std::vector<float> values;
  for (float t : times) push_hermite_key(values, position(t), velocity(t));
  b.animate(cam, "translation", times, values, "CUBICSPLINE");
  animate_look_at(b, cam, key_times(120, clip), position, target);

  add_sun(b, {0.45f, -0.8f, -0.4f}, 3.0f, {1.0f, 0.95f, 0.85f});
  add_point(b, "lantern", {0.0f, 4.2f, 3.6f}, 6.0f, {1.0f, 0.7f, 0.4f}, 20.0f);
}

// ---------------------------------------------------------------- fan (seed 004, Fan)

namespace {

// A fan: stand, motor and a rotor node spinning about its local +Z (towards the viewer). Returns the head
// node (which an oscillating fan turns about Y).
int add_fan(GltfBuilder& b, const std::string& name, glm::vec3 base, float scale, int blades, float rev_per_s,
            float clip, int body_mat, int blade_mat, bool oscillate) {
  MeshData stand;
  stand.append(cylinder(0.45f * scale, 0.08f * scale, 24), glm::mat4(1.0f));
  stand.append(cylinder(0.05f * scale, 1.45f * scale, 10, false), translate(0, 0.08f * scale, 0));
  static_mesh(b, name + "_stand", stand, body_mat, base);
  const int head = b.add_node(name + "_head", -1, base + glm::vec3(0.0f, 1.6f * scale, 0.0f));
  MeshData motor = cylinder(0.18f * scale, 0.4f * scale, 20);
  const int motor_node = b.add_node(name + "_motor", head, glm::vec3(0.0f, 0.0f, -0.3f * scale), quat_axis(kPi / 2, {1, 0, 0}));
  b.set_mesh(motor_node, b.add_mesh(name + "_motor", motor, body_mat));
  const int rotor = b.add_node(name + "_rotor", head, glm::vec3(0.0f, 0.0f, 0.12f * scale));
  MeshData fan;
  fan.append(cylinder(0.12f * scale, 0.1f * scale, 16), rotate_x(kPi / 2) * translate(0, -0.05f * scale, 0));
  for (int k = 0; k < blades; ++k) {
    const float a = kTwoPi * static_cast<float>(k) / static_cast<float>(blades);
    // Blade along +Y from the hub, pitched 25 degrees about its long axis.
    fan.append(box({0.34f * scale, 1.1f * scale, 0.025f * scale}),
               rotate_z(a) * translate(0, 0.65f * scale, 0) * rotate_y(deg(25.0f)));
  }
  b.set_mesh(rotor, b.add_mesh(name + "_blades", fan, blade_mat));
  // Spin: keys every 45 degrees (slerp is then exactly uniform), clockwise seen from the front.
  const int keys = static_cast<int>(std::lround(8.0f * rev_per_s * clip));
  std::vector<float> times = key_times(keys, clip), values;
  for (float t : times) push_quat(values, quat_axis(-kTwoPi * rev_per_s * t, {0, 0, 1}));
  b.animate(rotor, "rotation", times, values);
  if (oscillate) {
    // Oscillating head: +-35 degrees of yaw, one back-and-forth per clip.
    times = key_times(32, clip);
    values.clear();
    for (float t : times) push_quat(values, quat_axis(deg(35.0f) * std::sin(kTwoPi * t / clip), {0, 1, 0}));
    b.animate(head, "rotation", times, values);
  }
  return head;
}

}  // namespace

void build_fan(GltfBuilder& b) {
  const float clip = 2.0f;
  b.set_clip_name("spin");
  add_ground(b, 12.0f, 256, 8, 8.0f, {0.60f, 0.45f, 0.30f}, {0.50f, 0.36f, 0.24f}, 4);
  const int wall_tex = b.add_texture(bricks("wall_bricks", 256, 16, {0.60f, 0.30f, 0.22f}, {0.80f, 0.78f, 0.74f}));
  MeshData wall = box({10.0f, 5.0f, 0.3f});
  scale_uv(wall, 5.0f, 2.5f);
  static_mesh(b, "wall", wall, simple_material(b, "wall", {1, 1, 1}, 0.9f, wall_tex), {0.0f, 2.5f, -2.0f});
  const int metal = simple_material(b, "fan_body", {0.25f, 0.27f, 0.3f}, 0.35f, -1, 0.8f);
  const int blade_big = simple_material(b, "blades_white", {0.9f, 0.9f, 0.88f}, 0.4f);
  const int blade_small = simple_material(b, "blades_blue", {0.15f, 0.35f, 0.75f}, 0.4f);
  add_fan(b, "big_fan", {0.0f, 0.0f, 0.0f}, 1.0f, 5, 1.5f, clip, metal, blade_big, false);
  // A small table with a faster, oscillating three-blade fan.
  static_mesh(b, "table", box({1.0f, 0.7f, 0.7f}), simple_material(b, "table", {0.35f, 0.22f, 0.12f}, 0.7f), {-2.3f, 0.35f, 0.4f});
  add_fan(b, "desk_fan", {-2.3f, 0.7f, 0.4f}, 0.45f, 3, 3.0f, clip, metal, blade_small, true);

  add_static_camera(b, "front", {0.9f, 1.7f, 4.6f}, {-0.5f, 1.3f, 0.0f}, 0.75f, 0.2f, 30.0f);
  add_sun(b, {-0.3f, -1.0f, -0.6f}, 1.5f, {1.0f, 0.97f, 0.92f});
  add_point(b, "lamp", {1.5f, 3.5f, 2.5f}, 60.0f, {1.0f, 0.9f, 0.75f});
}

// ---------------------------------------------------------------- fence (seed 003, flicker)

void build_fence(GltfBuilder& b) {
  const float clip = 8.0f;
  b.set_clip_name("drift");
  // Fine checker: 6 cm squares, far below a pixel in the distance.
  add_ground(b, 60.0f, 256, 32, 30.0f, {0.78f, 0.78f, 0.74f}, {0.20f, 0.20f, 0.22f}, 10);
  const int paint = simple_material(b, "fence_paint", {0.92f, 0.92f, 0.88f}, 0.6f);
  const int iron = simple_material(b, "railing_iron", {0.08f, 0.08f, 0.09f}, 0.4f, -1, 0.9f);

  // Picket fence along X (171 slats, 5 cm wide) and a second one further back at an angle.
  MeshData fence;
  for (int k = 0; k <= 170; ++k) fence.append(box({0.05f, 1.1f, 0.02f}), translate(-12.0f + 0.14f * static_cast<float>(k), 0.55f, 0.0f));
  fence.append(box({24.0f, 0.06f, 0.03f}), translate(0.0f, 0.3f, -0.025f));
  fence.append(box({24.0f, 0.06f, 0.03f}), translate(0.0f, 0.85f, -0.025f));
  static_mesh(b, "fence_near", fence, paint, {0.0f, 0.0f, -3.0f});
  static_mesh(b, "fence_far", fence, paint, {2.0f, 0.0f, -9.0f}, quat_axis(deg(20.0f), {0, 1, 0}));

  // Balcony-like railing: 1.2 cm bars every 10 cm and a top rail.
  MeshData railing;
  for (int k = 0; k <= 80; ++k) railing.append(cylinder(0.012f, 1.0f, 6, false), translate(-6.0f + 0.1f * static_cast<float>(k), 0.0f, 0.0f));
  railing.append(box({8.1f, 0.04f, 0.05f}), translate(-2.0f, 1.0f, 0.0f));
  static_mesh(b, "railing", railing, iron, {0.0f, 0.0f, 1.5f});

  // Brick wall at the back: high-frequency texture.
  MeshData wall = box({24.0f, 4.0f, 0.4f});
  scale_uv(wall, 24.0f, 4.0f);
  static_mesh(b, "wall", wall,
              simple_material(b, "wall", {1, 1, 1}, 0.9f, b.add_texture(bricks("wall_bricks", 256, 16, {0.58f, 0.32f, 0.24f}, {0.82f, 0.8f, 0.76f}))),
              {0.0f, 2.0f, -14.0f});

  // Foliage: trunks with crowns of crossed alpha-MASK leaf cards that sway in the wind.
  MaterialDesc leaves_mat;
  leaves_mat.name = "leaves";
  leaves_mat.texture = b.add_texture(leaves("leaf_atlas", 256, 110));
  leaves_mat.alpha_mode = "MASK";
  leaves_mat.alpha_cutoff = 0.5f;
  leaves_mat.double_sided = true;
  leaves_mat.roughness = 0.7f;
  const int leaf = b.add_material(leaves_mat);
  const int bark = simple_material(b, "bark", {0.30f, 0.22f, 0.15f}, 0.9f);
  const glm::vec3 plants[7] = {{-7.0f, 0, -5.0f}, {-3.5f, 0, -6.2f}, {0.5f, 0, -5.5f}, {4.0f, 0, -6.5f},
                               {7.5f, 0, -5.2f}, {-5.0f, 0, -1.0f}, {5.5f, 0, -1.6f}};
  for (int p = 0; p < 7; ++p) {
    const auto up = static_cast<std::uint32_t>(p);
    const float h = 1.3f + 1.2f * hash01(up, 21u);
    static_mesh(b, "trunk" + std::to_string(p), cylinder(0.07f, h, 8), bark, plants[p]);
    MeshData crown;
    for (int c = 0; c < 12; ++c) {
      const auto uc = static_cast<std::uint32_t>(c);
      const glm::vec3 off(0.5f * (hash01(up, 100u + uc) - 0.5f), 0.6f * (hash01(up, 200u + uc) - 0.5f),
                          0.5f * (hash01(up, 300u + uc) - 0.5f));
      const glm::mat4 xf = translate(off.x, off.y, off.z) * rotate_y(kPi * hash01(up, 400u + uc)) *
                           rotate_x(0.6f * (hash01(up, 500u + uc) - 0.5f));
      crown.append(quad(1.3f, 1.3f), xf);
    }
    const int node = b.add_node("crown" + std::to_string(p), -1, plants[p] + glm::vec3(0.0f, h + 0.3f, 0.0f));
    b.set_mesh(node, b.add_mesh("crown" + std::to_string(p), crown, leaf));
    // Sway: two periods per clip, a few degrees, each plant with its own phase.
    std::vector<float> times = key_times(32, clip), values;
    const float phase = kTwoPi * hash01(up, 31u);
    for (float t : times) {
      const float s = kTwoPi * 2.0f * t / clip + phase;
      push_quat(values, quat_axis(deg(4.0f) * std::sin(s), {0, 0, 1}) * quat_axis(deg(2.5f) * std::sin(1.0f * s + 1.0f), {1, 0, 0}));
    }
    b.animate(node, "rotation", times, values);
  }

  // Camera: a slow, non-linear drift (the PHLM paper avoids plain pans): a closed Catmull-Rom CUBICSPLINE
  // through five points, looking at a point that slides along the near fence.
  const std::vector<glm::vec3> pts = {{-5.0f, 1.6f, 6.0f}, {-2.0f, 1.3f, 4.8f}, {1.0f, 1.8f, 5.5f}, {3.5f, 1.4f, 4.5f}};
  const int n = static_cast<int>(pts.size());
  const float seg = clip / static_cast<float>(n);
  auto point = [&](int k) { return pts[static_cast<std::size_t>(((k % n) + n) % n)]; };
  auto tangent = [&](int k) { return (point(k + 1) - point(k - 1)) / (2.0f * seg); };  // per second
  auto position = [&](float t) {
    // The Hermite curve the CUBICSPLINE keys describe (glTF Appendix C), for the look-at orientation.
    const int k = std::min(static_cast<int>(t / seg), n - 1);
    const float s = (t - static_cast<float>(k) * seg) / seg, s2 = s * s, s3 = s2 * s;
    return (2 * s3 - 3 * s2 + 1) * point(k) + (s3 - 2 * s2 + s) * seg * tangent(k) + (-2 * s3 + 3 * s2) * point(k + 1) +
           (s3 - s2) * seg * tangent(k + 1);
  };
  auto target = [&](float t) { return glm::vec3(3.0f * std::sin(kTwoPi * t / clip), 0.7f, -3.0f); };
  const int cam = b.add_node("drift_camera", -1, position(0.0f), look_rotation(target(0.0f) - position(0.0f)));
  b.set_camera(cam, "drift", 0.8f, 0.1f, 80.0f);
  std::vector<float> values;
  for (int k = 0; k <= n; ++k) push_hermite_key(values, point(k), tangent(k));
  b.animate(cam, "translation", key_times(n, clip), values, "CUBICSPLINE");
  animate_look_at(b, cam, key_times(160, clip), position, target);

  add_sun(b, {0.7f, -0.45f, -0.55f}, 3.0f, {1.0f, 0.92f, 0.8f});
  add_point(b, "sky_fill", {0.0f, 6.0f, 8.0f}, 50.0f, {0.6f, 0.7f, 1.0f});
}

// ---------------------------------------------------------------- morph_test

void build_morph_test(GltfBuilder& b) {
  const float clip = 2.0f;
  b.set_clip_name("wave");
  add_ground(b, 6.0f, 64, 4, 3.0f, {0.5f, 0.55f, 0.5f}, {0.35f, 0.4f, 0.35f}, 2);
  // A 1.5 x 1 m flag of 12 x 8 quads in the XY plane, hanging from a pole at x = 0.
  MeshData flag;
  const int nx = 12, ny = 8;
  const float w = 1.5f, h = 1.0f;
  std::vector<glm::vec3> wave0, wave1;
  for (int j = 0; j <= ny; ++j) {
    for (int i = 0; i <= nx; ++i) {
      const float u = static_cast<float>(i) / nx, v = static_cast<float>(j) / ny;
      flag.positions.push_back({u * w, v * h, 0.0f});
      flag.normals.push_back({0, 0, 1});
      flag.texcoords.push_back({u, 1.0f - v});
      // Target 0: a travelling-wave crest; target 1: a sag of the free corner. Both grow with distance from the pole.
      wave0.push_back({0.0f, 0.0f, 0.18f * u * std::sin(kTwoPi * u)});
      wave1.push_back({-0.05f * u, -0.08f * u * (1.0f - v), 0.12f * u * std::cos(kPi * v)});
    }
  }
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      const auto a = static_cast<std::uint32_t>(j * (nx + 1) + i), r = static_cast<std::uint32_t>(nx + 1);
      flag.indices.insert(flag.indices.end(), {a, a + 1, a + r + 1, a, a + r + 1, a + r});
    }
  }
  flag.morph_positions = {wave0, wave1};
  MaterialDesc cloth;
  cloth.name = "flag";
  cloth.texture = b.add_texture(checker("flag_checker", 64, 4, {0.85f, 0.1f, 0.1f}, {0.95f, 0.95f, 0.92f}));
  cloth.double_sided = true;
  const int flag_node = b.add_node("flag", -1, glm::vec3(0.05f, 1.0f, 0.0f));
  b.set_mesh(flag_node, b.add_mesh("flag", flag, b.add_material(cloth), {0.0f, 0.0f}));
  std::vector<float> times = key_times(20, clip), values;
  for (float t : times) {
    const float a = kTwoPi * t / clip;
    values.insert(values.end(), {0.5f + 0.5f * std::sin(a), 0.5f - 0.5f * std::cos(a)});
  }
  b.animate(flag_node, "weights", times, values);
  static_mesh(b, "pole", cylinder(0.03f, 2.1f, 10), simple_material(b, "pole", {0.6f, 0.6f, 0.62f}, 0.3f, -1, 1.0f));

  add_static_camera(b, "front", {0.9f, 1.5f, 3.2f}, {0.75f, 1.4f, 0.0f}, 0.7f, 0.1f, 20.0f);
  add_sun(b, {-0.4f, -0.9f, -0.5f}, 3.0f, {1.0f, 0.97f, 0.92f});
}

const std::vector<SceneRecipe>& recipes() {
  static const std::vector<SceneRecipe> list = {
      {"walkers", "two skinned quadrupeds trotting round a yard, static camera (demo default; seed 000 horses)", build_walkers},
      {"tower", "camera circling a tower behind two rings of columns: fast disocclusions (seed 004 Tower)", build_tower},
      {"fan", "two spinning fans before a brick wall: rotational motion (seed 004 Fan)", build_fan},
      {"fence", "fences, railing, fine checker and swaying cut-out foliage under a drifting camera (seed 003)", build_fence},
      {"morph_test", "a flag waving through two morph targets (tests of morphed motion vectors)", build_morph_test},
  };
  return list;
}

}  // namespace scenegen
