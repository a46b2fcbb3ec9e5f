// scene-generator: writes the project's built-in scenes (assets/scenes), each as glTF and as text USD.
//   scene-generator OUT_DIR [NAME...]   writes OUT_DIR/NAME.glb, OUT_DIR/NAME.usda and OUT_DIR/textures/NAME.*.png
//                                       for the named scenes (all when none)
//   scene-generator --list              lists the scenes
// The output is byte-for-byte reproducible (see gltf_builder.h); tests/scene checks that the committed
// files are what this program writes.
#include "scenes.h"
#include "usda_writer.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace {

// Writes through a temporary file and a rename, so an interrupted run leaves no truncated file.
bool write_file(const std::filesystem::path& path, const void* data, std::size_t size) {
  const auto tmp = std::filesystem::path(path.string() + ".tmp");
  {
    std::ofstream out(tmp, std::ios::binary);
    out.write(static_cast<const char*>(data), static_cast<std::streamsize>(size));
    if (!out) {
      std::fprintf(stderr, "scene-generator: %s: cannot write\n", tmp.string().c_str());
      return false;
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) std::fprintf(stderr, "scene-generator: %s: %s\n", path.string().c_str(), ec.message().c_str());
  return !ec;
}

}  // namespace

int main(int argc, char** argv) {
  const std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty() || args[0] == "--help" || args[0] == "-h") {
    std::fprintf(stderr, "usage: scene-generator OUT_DIR [NAME...] | --list\n");
    return args.empty() ? 1 : 0;
  }
  if (args[0] == "--list") {
    for (const auto& r : scenegen::recipes()) std::printf("%-11s %s\n", r.name.c_str(), r.description.c_str());
    return 0;
  }
  const std::filesystem::path out_dir = args[0];
  std::error_code ec;
  std::filesystem::create_directories(out_dir / "textures", ec);
  std::vector<std::string> wanted(args.begin() + 1, args.end());
  for (const auto& name : wanted) {
    bool known = false;
    for (const auto& r : scenegen::recipes()) known = known || r.name == name;
    if (!known) {
      std::fprintf(stderr, "scene-generator: no scene '%s' (see --list)\n", name.c_str());
      return 1;
    }
  }
  for (const auto& r : scenegen::recipes()) {
    if (!wanted.empty() && std::find(wanted.begin(), wanted.end(), r.name) == wanted.end()) continue;
    scenegen::GltfBuilder builder;
    r.build(builder);
    const std::vector<unsigned char> bytes = builder.glb();
    if (!write_file(out_dir / (r.name + ".glb"), bytes.data(), bytes.size())) return 4;
    std::vector<scenegen::TextureFile> textures;
    std::string error;
    const std::string usda = scenegen::write_usda(builder.model(), r.name, textures, error);
    if (usda.empty()) {
      std::fprintf(stderr, "scene-generator: %s: cannot write it as USD: %s\n", r.name.c_str(), error.c_str());
      return 5;
    }
    if (!write_file(out_dir / (r.name + ".usda"), usda.data(), usda.size())) return 4;
    for (const auto& t : textures)
      if (!write_file(out_dir / t.path, t.png.data(), t.png.size())) return 4;
    std::printf("%-11s %7zu triangles %8zu bytes .glb %8zu bytes .usda + %zu textures  %s\n", r.name.c_str(),
                builder.triangle_count(), bytes.size(), usda.size(), textures.size(), (out_dir / r.name).string().c_str());
  }
  return 0;
}
