// scene-generator: writes the project's built-in scenes (assets/scenes/*.glb).
//   scene-generator OUT_DIR [NAME...]   writes OUT_DIR/NAME.glb for the named scenes (all when none)
//   scene-generator --list              lists the scenes
// The output is byte-for-byte reproducible (see gltf_builder.h); tests/scene checks that the committed
// files are what this program writes.
#include "scenes.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

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
  std::filesystem::create_directories(out_dir, ec);
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
    const auto path = out_dir / (r.name + ".glb");
    const auto tmp = out_dir / (r.name + ".glb.tmp");
    {
      std::ofstream out(tmp, std::ios::binary);
      out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
      if (!out) {
        std::fprintf(stderr, "scene-generator: %s: cannot write\n", tmp.string().c_str());
        return 4;
      }
    }
    std::filesystem::rename(tmp, path, ec);
    if (ec) {
      std::fprintf(stderr, "scene-generator: %s: %s\n", path.string().c_str(), ec.message().c_str());
      return 4;
    }
    std::printf("%-11s %7zu triangles %8zu bytes  %s\n", r.name.c_str(), builder.triangle_count(), bytes.size(),
                path.string().c_str());
  }
  return 0;
}
