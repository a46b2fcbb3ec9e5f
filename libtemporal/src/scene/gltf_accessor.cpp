// Bounds-checked glTF accessor reads; see gltf_accessor.h.
#include "gltf_accessor.h"

#include <algorithm>
#include <cstring>

namespace temporal::scene_detail {
namespace {

const char* type_name(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR: return "SCALAR";
    case TINYGLTF_TYPE_VEC2: return "VEC2";
    case TINYGLTF_TYPE_VEC3: return "VEC3";
    case TINYGLTF_TYPE_VEC4: return "VEC4";
    case TINYGLTF_TYPE_MAT2: return "MAT2";
    case TINYGLTF_TYPE_MAT3: return "MAT3";
    case TINYGLTF_TYPE_MAT4: return "MAT4";
    default: return "unknown";
  }
}

// Decodes one component at p as double (normalised when asked).
double load_component(const unsigned char* p, int component_type, bool normalized) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT: { float v; std::memcpy(&v, p, 4); return v; }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: { const std::uint8_t v = *p; return normalized ? v / 255.0 : v; }
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      std::int8_t v; std::memcpy(&v, p, 1);
      return normalized ? std::max(v / 127.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      std::uint16_t v; std::memcpy(&v, p, 2);
      return normalized ? v / 65535.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      std::int16_t v; std::memcpy(&v, p, 2);
      return normalized ? std::max(v / 32767.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: { std::uint32_t v; std::memcpy(&v, p, 4); return v; }
    case TINYGLTF_COMPONENT_TYPE_INT: { std::int32_t v; std::memcpy(&v, p, 4); return v; }
    case TINYGLTF_COMPONENT_TYPE_DOUBLE: { double v; std::memcpy(&v, p, 8); return v; }
    default: return 0.0;
  }
}

// Locates `count` elements of `elem_bytes` bytes at `offset` in buffer view `view` with stride `stride`
// (0: tightly packed) and checks every bound. Returns the first element's address.
Expected<const unsigned char*> locate(const tinygltf::Model& model, int view, std::size_t offset,
                                      std::size_t count, std::size_t elem_bytes, std::size_t* stride_out,
                                      const std::string& file, const std::string& what) {
  if (view < 0 || view >= static_cast<int>(model.bufferViews.size())) {
    return Error::input(file, what + ": buffer view " + std::to_string(view) + " does not exist (the file has " +
                                  std::to_string(model.bufferViews.size()) + ")");
  }
  const tinygltf::BufferView& bv = model.bufferViews[static_cast<std::size_t>(view)];
  if (bv.buffer < 0 || bv.buffer >= static_cast<int>(model.buffers.size())) {
    return Error::input(file, what + ": buffer view " + std::to_string(view) + " names buffer " +
                                  std::to_string(bv.buffer) + ", which does not exist");
  }
  const std::vector<unsigned char>& data = model.buffers[static_cast<std::size_t>(bv.buffer)].data;
  if (bv.byteOffset > data.size() || bv.byteLength > data.size() - bv.byteOffset) {
    return Error::input(file, what + ": buffer view " + std::to_string(view) + " (bytes " +
                                  std::to_string(bv.byteOffset) + " + " + std::to_string(bv.byteLength) +
                                  ") runs past the end of buffer " + std::to_string(bv.buffer) + " (" +
                                  std::to_string(data.size()) + " bytes): the .bin file is truncated or wrong");
  }
  const std::size_t stride = bv.byteStride != 0 ? bv.byteStride : elem_bytes;
  if (stride < elem_bytes) {
    return Error::input(file, what + ": byte stride " + std::to_string(stride) + " is smaller than one element (" +
                                  std::to_string(elem_bytes) + " bytes)");
  }
  if (count > 0) {
    const std::size_t length = bv.byteLength;
    // count * stride could overflow for an absurd count: compare in steps.
    if (offset > length || elem_bytes > length - offset || (count - 1) > (length - offset - elem_bytes) / stride) {
      return Error::input(file, what + ": accessor reads " + std::to_string(count) + " elements of " +
                                    std::to_string(elem_bytes) + " bytes from offset " + std::to_string(offset) +
                                    " but buffer view " + std::to_string(view) + " holds only " +
                                    std::to_string(length) + " bytes (accessor out of range)");
    }
  }
  *stride_out = stride;
  return data.data() + bv.byteOffset + offset;
}

// Reads accessor `index` into doubles-converted-to-T through `convert`.
template <typename T>
Status read_accessor(const tinygltf::Model& model, int index, int components, const std::string& file,
                     const std::string& what, bool integer_only, std::vector<T>& out) {
  if (index < 0 || index >= static_cast<int>(model.accessors.size())) {
    return Error::input(file, what + ": accessor " + std::to_string(index) + " does not exist (the file has " +
                                  std::to_string(model.accessors.size()) + ")");
  }
  const tinygltf::Accessor& acc = model.accessors[static_cast<std::size_t>(index)];
  const std::string name = what + " (accessor " + std::to_string(index) + ")";
  const int n_comp = tinygltf::GetNumComponentsInType(static_cast<std::uint32_t>(acc.type));
  const int comp_bytes = tinygltf::GetComponentSizeInBytes(static_cast<std::uint32_t>(acc.componentType));
  if (n_comp <= 0 || comp_bytes <= 0) {
    return Error::input(file, name + ": unknown type or component type");
  }
  if (components > 0 && n_comp != components) {
    return Error::input(file, name + ": type " + type_name(acc.type) + " has " + std::to_string(n_comp) +
                                  " components, expected " + std::to_string(components));
  }
  if (integer_only && acc.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
      acc.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
      acc.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT) {
    return Error::input(file, name + ": component type must be an unsigned integer (5121, 5123 or 5125), got " +
                                  std::to_string(acc.componentType));
  }
  const std::size_t count = acc.count;
  const std::size_t nc = static_cast<std::size_t>(n_comp);
  const std::size_t elem = nc * static_cast<std::size_t>(comp_bytes);
  // Bounds first, allocation second: a corrupt count must not allocate terabytes.
  const unsigned char* p = nullptr;
  std::size_t stride = 0;
  if (acc.bufferView >= 0) {
    auto base = locate(model, acc.bufferView, acc.byteOffset, count, elem, &stride, file, name);
    if (!base) return base.error();
    p = *base;
  } else if (count > (std::size_t{1} << 26)) {
    return Error::input(file, name + ": " + std::to_string(count) + " elements without a buffer view (corrupt count)");
  }
  out.assign(count * nc, T(0));
  if (p != nullptr) {
    for (std::size_t i = 0; i < count; ++i, p += stride) {
      for (std::size_t c = 0; c < nc; ++c) {
        out[i * nc + c] = static_cast<T>(load_component(p + c * static_cast<std::size_t>(comp_bytes),
                                                        acc.componentType, acc.normalized));
      }
    }
  }
  if (acc.sparse.isSparse) {
    // Sparse substitution (section 3.6.2.3): `count` indices into the accessor and the values to put there.
    const std::size_t sc = static_cast<std::size_t>(std::max(acc.sparse.count, 0));
    const int ict = acc.sparse.indices.componentType;
    const int ibytes = tinygltf::GetComponentSizeInBytes(static_cast<std::uint32_t>(ict));
    if (ibytes <= 0 || ict == TINYGLTF_COMPONENT_TYPE_FLOAT) {
      return Error::input(file, name + ": sparse indices have an invalid component type");
    }
    std::size_t istride = 0, vstride = 0;
    auto ibase = locate(model, acc.sparse.indices.bufferView,
                        static_cast<std::size_t>(std::max(acc.sparse.indices.byteOffset, 0)), sc,
                        static_cast<std::size_t>(ibytes), &istride, file, name + " sparse indices");
    if (!ibase) return ibase.error();
    auto vbase = locate(model, acc.sparse.values.bufferView,
                        static_cast<std::size_t>(std::max(acc.sparse.values.byteOffset, 0)), sc, elem, &vstride,
                        file, name + " sparse values");
    if (!vbase) return vbase.error();
    istride = static_cast<std::size_t>(ibytes);  // sparse data is tightly packed
    vstride = elem;
    for (std::size_t s = 0; s < sc; ++s) {
      const auto target = static_cast<std::size_t>(load_component(*ibase + s * istride, ict, false));
      if (target >= count) {
        return Error::input(file, name + ": sparse index " + std::to_string(target) + " is out of range (count " +
                                      std::to_string(count) + ")");
      }
      for (std::size_t c = 0; c < nc; ++c) {
        out[target * nc + c] = static_cast<T>(load_component(*vbase + s * vstride + c * static_cast<std::size_t>(comp_bytes),
                                                             acc.componentType, acc.normalized));
      }
    }
  }
  return Status::ok();
}

}  // namespace

Status read_floats(const tinygltf::Model& model, int index, int components, const std::string& file,
                   const std::string& what, std::vector<float>& out) {
  return read_accessor<float>(model, index, components, file, what, false, out);
}

Status read_uints(const tinygltf::Model& model, int index, int components, const std::string& file,
                  const std::string& what, std::vector<std::uint32_t>& out) {
  return read_accessor<std::uint32_t>(model, index, components, file, what, true, out);
}

Expected<std::size_t> accessor_count(const tinygltf::Model& model, int index, const std::string& file,
                                     const std::string& what) {
  if (index < 0 || index >= static_cast<int>(model.accessors.size())) {
    return Error::input(file, what + ": accessor " + std::to_string(index) + " does not exist (the file has " +
                                  std::to_string(model.accessors.size()) + ")");
  }
  return model.accessors[static_cast<std::size_t>(index)].count;
}

}  // namespace temporal::scene_detail
