#include "usd_reader.h"
namespace temporal::scene_detail {
Status read_usd(const std::string& path, const SceneLoadOptions&, SceneDescription&) {
  return Error::input(path, "USD is not read yet");
}
}  // namespace temporal::scene_detail
