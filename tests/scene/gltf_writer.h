// Tiny hand-written glTF files for the scene tests: a JSON text plus one binary buffer of floats and
// integers, written to a scratch folder. Each test builds exactly the case it checks, so the expected
// values can be computed by hand.
#pragma once

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace temporal::test {

// Accumulates binary data and the matching bufferViews/accessors JSON.
class GltfBuffer {
 public:
  // Appends floats as an accessor of `type` ("SCALAR", "VEC3", ...); returns the accessor index.
  int add_floats(const std::vector<float>& values, const std::string& type) {
    const int comps = components(type);
    return add(values.data(), values.size() * 4, 5126, values.size() / static_cast<std::size_t>(comps), type);
  }
  // Appends unsigned shorts (indices, JOINTS_0).
  int add_ushorts(const std::vector<std::uint16_t>& values, const std::string& type) {
    const int comps = components(type);
    return add(values.data(), values.size() * 2, 5123, values.size() / static_cast<std::size_t>(comps), type);
  }
  // The "buffers", "bufferViews" and "accessors" members (with a trailing comma), for a buffer file `uri`.
  std::string json(const std::string& uri) const {
    return "\"buffers\": [{\"uri\": \"" + uri + "\", \"byteLength\": " + std::to_string(bytes_.size()) +
           "}],\n\"bufferViews\": [" + views_ + "],\n\"accessors\": [" + accessors_ + "],\n";
  }
  const std::vector<unsigned char>& bytes() const { return bytes_; }

 private:
  static int components(const std::string& type) {
    if (type == "SCALAR") return 1;
    if (type == "VEC2") return 2;
    if (type == "VEC3") return 3;
    if (type == "VEC4") return 4;
    return 16;  // MAT4
  }
  int add(const void* data, std::size_t size, int component_type, std::size_t count, const std::string& type) {
    while (bytes_.size() % 4) bytes_.push_back(0);
    const std::size_t offset = bytes_.size();
    bytes_.resize(offset + size);
    std::memcpy(bytes_.data() + offset, data, size);
    const int index = count_++;
    views_ += std::string(index ? ", " : "") + "{\"buffer\": 0, \"byteOffset\": " + std::to_string(offset) +
              ", \"byteLength\": " + std::to_string(size) + "}";
    accessors_ += std::string(index ? ", " : "") + "{\"bufferView\": " + std::to_string(index) +
                  ", \"componentType\": " + std::to_string(component_type) + ", \"count\": " + std::to_string(count) +
                  ", \"type\": \"" + type + "\"}";
    return index;
  }
  std::vector<unsigned char> bytes_;
  std::string views_, accessors_;
  int count_ = 0;
};

// Writes `dir/name.gltf` (with `body`, the members after the buffers) and `dir/name.bin`; returns the .gltf path.
inline std::string write_gltf(const std::filesystem::path& dir, const std::string& name, const GltfBuffer& buffer,
                              const std::string& body) {
  {
    std::ofstream bin(dir / (name + ".bin"), std::ios::binary);
    bin.write(reinterpret_cast<const char*>(buffer.bytes().data()), static_cast<std::streamsize>(buffer.bytes().size()));
  }
  const auto path = dir / (name + ".gltf");
  std::ofstream out(path);
  out << "{\n\"asset\": {\"version\": \"2.0\"},\n" << buffer.json(name + ".bin") << body << "\n}\n";
  return path.string();
}

}  // namespace temporal::test
