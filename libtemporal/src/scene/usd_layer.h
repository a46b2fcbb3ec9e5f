// One parsed USD text layer (.usda): the specs of the file exactly as authored, before composition
// (usd_stage.h composes layers). A reduced Sdf data model: prim specs with their metadata, list-edited
// composition arcs, variant sets and properties; property specs with a default value, time samples,
// relationship targets or attribute connections. Internal to src/scene.
//
// Values are parsed by their syntax: numbers become a flat array of doubles with the tuple size of each
// element (a point3f[] of n points: 3n numbers, tuple 3; a matrix4d: 16 numbers in the file's row order),
// strings, tokens and identifiers become strings, asset paths keep the text and the path resolved against
// the authoring layer's folder, prim and property paths are made absolute (relative ones against the prim
// that authors them).
#pragma once

#include "temporal/core/error.h"

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <vector>

namespace temporal::usd {

struct Value;
using Dictionary = std::vector<std::pair<std::string, Value>>;

struct Value {
  enum class Kind : std::uint8_t { Empty, None, Number, String, Asset, Path, Dict };
  Kind kind = Kind::Empty;        // Empty: nothing authored (or `[]` whose element kind is unknown)
  bool array = false;             // authored as [ ... ]
  int tuple = 1;                  // numbers per element: 1, 2, 3, 4, 9, 16 ...
  std::vector<double> numbers;    // Number: elements * tuple values (bools are 0 / 1)
  std::vector<std::string> text;  // String (also tokens and bare identifiers), Asset (as written), Path (absolute)
  std::vector<std::string> resolved;  // Asset: absolute file path ("" for an empty asset path)
  std::shared_ptr<const Dictionary> dict;  // Dict

  bool is_none() const { return kind == Kind::None; }
  // Elements: numbers / tuple, or strings.
  std::size_t size() const { return kind == Kind::Number ? numbers.size() / std::size_t(tuple > 0 ? tuple : 1) : text.size(); }
  const Value* find(std::string_view key) const;  // Dict entry, or nullptr
};

struct LayerOffset {
  double offset = 0.0, scale = 1.0;  // stage time = offset + scale * layer time
};

// An `@asset@</path>` reference or payload; an empty asset names a prim of the referencing layer stack.
struct Reference {
  std::string asset;     // as written
  std::string resolved;  // absolute path ("" for an internal reference)
  std::string prim;      // absolute prim path, or "" for the layer's defaultPrim
  LayerOffset offset;
  int line = 0, column = 0;
};

// An Sdf list op: `explicit` replaces weaker opinions; otherwise weaker lists are edited by deleting,
// prepending and appending (`add` counts as append, `reorder` is kept but not applied).
template <typename T>
struct ListOp {
  bool is_explicit = false;
  std::vector<T> explicit_items, prepended, appended, deleted;
  bool empty() const { return !is_explicit && prepended.empty() && appended.empty() && deleted.empty(); }
};

struct PropertySpec {
  std::string name;       // "points", "primvars:st", "xformOp:rotateXYZ", "material:binding" ...
  std::string type_name;  // "point3f", "token", "matrix4d" ... ("" for relationships)
  bool array = false;     // declared with []
  bool uniform = false;
  bool relationship = false;
  bool has_default = false;
  Value default_value;    // kind None for an explicit `= None` (a blocked value)
  std::vector<std::pair<double, Value>> time_samples;  // sorted by time code; None samples are blocks
  ListOp<std::string> targets;      // relationship targets (absolute paths)
  ListOp<std::string> connections;  // attribute connections (absolute property paths)
  Dictionary metadata;              // interpolation, elementSize, ...
  int line = 0, column = 0;
};

enum class Specifier : std::uint8_t { Def, Over, Class };

struct PrimSpec;

struct VariantSpec {
  std::string name;
  std::unique_ptr<PrimSpec> prim;  // the variant's opinions about the owning prim (name: the owner's)
};

struct VariantSetSpec {
  std::string name;
  std::vector<VariantSpec> variants;
  const PrimSpec* find(std::string_view variant) const;
};

struct PrimSpec {
  std::string name;
  std::string path;  // absolute path in the layer, without variant selections
  Specifier specifier = Specifier::Over;
  std::string type_name;
  Dictionary metadata;  // every metadatum not listed below (kind, instanceable, active, hidden, ...)
  ListOp<Reference> references, payloads;
  ListOp<std::string> inherits, specializes, variant_set_names, api_schemas;
  std::vector<std::pair<std::string, std::string>> variant_selections;  // set -> variant
  std::vector<PropertySpec> properties;
  std::vector<std::unique_ptr<PrimSpec>> children;
  std::vector<VariantSetSpec> variant_sets;
  int line = 0, column = 0;

  const PrimSpec* child(std::string_view name) const;
  const PropertySpec* property(std::string_view name) const;
  const VariantSetSpec* variant_set(std::string_view name) const;
  const std::string* variant_selection(std::string_view set) const;
  const Value* meta(std::string_view key) const;

  // Lookup tables (filled by the parser).
  std::unordered_map<std::string, std::size_t> child_index, property_index;
};

struct SubLayer {
  std::string asset, resolved;
  LayerOffset offset;
  int line = 0, column = 0;
};

struct Layer {
  std::string path;  // as opened (absolute)
  Dictionary metadata;
  std::vector<SubLayer> sublayers;
  std::string default_prim;
  PrimSpec root;     // the pseudo-root: its children are the layer's root prims

  // Layer metadata with USD's fallbacks.
  double number(std::string_view key, double fallback) const;
  std::string token(std::string_view key, const std::string& fallback) const;
  bool has(std::string_view key) const;
  // The prim at an absolute path (no variant selections), or nullptr.
  const PrimSpec* prim_at(std::string_view path) const;
};

// Parses USD text. `path` names the layer in messages and anchors its relative asset paths. Errors are
// Input errors whose file is `path:line:column` and whose message says what is wrong.
Expected<std::unique_ptr<Layer>> parse_usda(std::string_view text, const std::string& path);
// Reads and parses a file (refusing crate files and packages with the conversion hint).
Expected<std::unique_ptr<Layer>> read_usda(const std::string& path);

// "/a/b" + "c" -> "/a/b/c"; relative targets ("c", "../c", ".prop") against a prim path.
std::string absolute_path(std::string_view prim_path, std::string_view target);

// The node at the absolute prim path `path` ("/World/Mesh") below `root` (the pseudo-root "/"), one path element at
// a time through Node::child(name); nullptr for a relative path or a missing prim. Node is a layer's PrimSpec
// (Layer::prim_at) or the composed stage's Prim (Stage::prim_at).
template <typename Node>
const Node* descend_path(const Node* root, std::string_view path) {
  if (path.empty() || path[0] != '/') return nullptr;
  const Node* p = root;
  std::size_t i = 1;
  while (p && i < path.size()) {
    std::size_t j = path.find('/', i);
    if (j == std::string_view::npos) j = path.size();
    p = p->child(path.substr(i, j - i));
    i = j + 1;
  }
  return p;
}

}  // namespace temporal::usd
