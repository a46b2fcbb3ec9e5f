// Bounds-checked reading of glTF accessors (glTF 2.0 section 3.6). tinygltf parses the JSON and loads the
// buffers but does not check that an accessor lies inside its buffer view and buffer: every read here does,
// so a corrupt file gives an Input error instead of a read past the end.
#pragma once

#include "temporal/core/error.h"

#include <tiny_gltf.h>

#include <cstdint>
#include <string>
#include <vector>

namespace temporal::scene_detail {

// Reads accessor `index` as float values, `components` per element (0: any; the count is then
// GetNumComponentsInType). Normalised integer components are decoded per section 3.11 (e.g. a normalised
// unsigned byte c gives c / 255), other integers are converted as they are. Sparse accessors are applied.
// `what` names the use for the error message ("POSITION of mesh 'horse'").
Status read_floats(const tinygltf::Model& model, int index, int components, const std::string& file,
                   const std::string& what, std::vector<float>& out);

// Reads an accessor of unsigned integer components (indices, JOINTS_n) as uint32 values.
Status read_uints(const tinygltf::Model& model, int index, int components, const std::string& file,
                  const std::string& what, std::vector<std::uint32_t>& out);

// Number of elements of accessor `index`, or an error when the index is out of range.
Expected<std::size_t> accessor_count(const tinygltf::Model& model, int index, const std::string& file,
                                     const std::string& what);

}  // namespace temporal::scene_detail
