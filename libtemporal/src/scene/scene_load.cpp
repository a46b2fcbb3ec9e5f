// Scene::load: recognises the format by the file's content, lets its reader fill the format-neutral
// description, then finishes the scene (bounds, camera, key light: scene_finish.cpp).
#include "gltf_reader.h"
#include "scene_description.h"
#include "usd_reader.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>

namespace temporal {
namespace {

enum class Format { Gltf, Usda, UsdCrate, Usdz };

std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

// The content decides: "#usda" starts a text layer, "PXR-USDC" a crate file, "PK\3\4" a zip (.usdz); anything
// else goes to the glTF reader (JSON or the "glTF" magic of .glb), which says what is wrong with it. A .usd/.usda
// file whose content is neither text USD nor crate is refused as USD rather than reported as bad glTF.
Expected<Format> sniff(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char head[16] = {};
  in.read(head, sizeof head);
  const std::string h(head, static_cast<std::size_t>(in.gcount()));
  const std::string ext = lower_extension(path);
  if (h.rfind("#usda", 0) == 0 || h.rfind("\xEF\xBB\xBF#usda", 0) == 0) return Format::Usda;
  if (h.rfind("PXR-USDC", 0) == 0) return Format::UsdCrate;
  if (h.rfind("PK\x03\x04", 0) == 0 && (ext == ".usdz" || ext == ".usd" || ext == ".usdc")) return Format::Usdz;
  if (ext == ".usd" || ext == ".usda" || ext == ".usdc" || ext == ".usdz") {
    return Error::input(path, "not a text USD file: a .usda layer starts with '#usda 1.0' (this one starts with '" +
                                  h.substr(0, std::min<std::size_t>(h.find('\n'), 12)) + "')");
  }
  return Format::Gltf;
}

}  // namespace

Expected<Scene> Scene::load(const std::string& path, const SceneLoadOptions& options) {
  // The readers validate before they read; the guard turns what is left (an allocation that a corrupt but
  // in-bounds file can still ask for) into an Input error instead of a crash.
  try {
    return load_checked(path, options);
  } catch (const std::exception& e) {
    return Error::input(path, std::string("cannot load the scene: ") + e.what());
  }
}

Expected<Scene> Scene::load_checked(const std::string& path, const SceneLoadOptions& options) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    // A path that cannot be examined (a symbolic link loop, no permission) says why.
    return Error::input(path, ec && ec != std::errc::no_such_file_or_directory
                                  ? "cannot be examined: " + ec.message()
                                  : "no such file (give a .gltf, .glb or text .usda/.usd scene)");
  }
  if (options.camera.path != CameraOptions::Path::Fixed && !(options.camera.path_period_s > 0.0)) {
    return Error::usage("the camera path period must be positive (--camera-period)");
  }
  auto format = sniff(path);
  if (!format) return format.error();
  Scene scene;
  scene_detail::SceneDescription& d = *scene.impl_;
  switch (*format) {
    case Format::Gltf:
      if (Status s = scene_detail::read_gltf(path, options, d); !s) return s.error();
      break;
    case Format::Usda:
      if (Status s = scene_detail::read_usd(path, options, d); !s) return s.error();
      break;
    case Format::UsdCrate:
    case Format::Usdz:
      return Error::input(path, std::string(*format == Format::Usdz ? "a .usdz package" : "a binary USD (crate) file") +
                                    ", which cannot be read without OpenUSD; convert it to text on a machine with "
                                    "OpenUSD: usdcat -o file.usda " + std::filesystem::path(path).filename().string());
  }
  if (Status s = scene.finish(options); !s) return s.error();
  return scene;
}

}  // namespace temporal
