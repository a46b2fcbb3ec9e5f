// Composition of USD text layers into a stage: layer stacks (subLayers), references, payloads (always
// loaded), inherits, specializes and variant sets with their selections, in the strength order of OpenUSD's
// prim indexing (LIVRPS: local, inherits, variants, references, payloads, specializes; an arc's target
// weaker than the site that introduces it, stronger than that site's weaker siblings). Each composed prim
// keeps the specs that contribute to it, strongest first, with the mapping of their paths and times into
// the stage; values, relationship targets and connections are resolved from them on demand.
// What is simplified (docs/usd.md): list ops are composed per spec rather than across a layer stack, no
// relocates, no implied inherits across references, variant fallbacks only from authored selections.
// Internal to src/scene.
#pragma once

#include "usd_layer.h"

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace temporal::usd {

// Maps paths of a site's layer namespace into the stage: `from` (and below) becomes `to`, then the outer map.
struct PathMap {
  std::string from, to;
  std::shared_ptr<const PathMap> outer;
  // The stage path of `path`, or nullopt when it lies outside what the arcs map (such targets are dropped,
  // as OpenUSD does).
  std::optional<std::string> translate(const std::string& path) const;
};

// One contributing spec.
struct Site {
  const Layer* layer = nullptr;
  const PrimSpec* spec = nullptr;
  std::shared_ptr<const PathMap> map;
  LayerOffset offset;  // stage time code = offset + scale * time code in this layer
};

struct Prim {
  std::string name, path;
  std::string type_name;              // strongest authored
  Specifier specifier = Specifier::Over;  // strongest def/class, else over
  bool active = true;
  bool abstract = false;              // a class or below one
  std::vector<Site> sites;            // strongest first
  std::vector<std::unique_ptr<Prim>> children;
  const Prim* parent = nullptr;

  bool defined() const { return specifier == Specifier::Def && !abstract; }
  const Prim* child(std::string_view name) const;
  // Strongest spec of a property (the first site that has it), with its site.
  const PropertySpec* property(std::string_view name, const Site** site = nullptr) const;
  // The strongest opinion that has a value (time samples or a default), or nullptr when none or blocked (None).
  const PropertySpec* attribute(std::string_view name, const Site** site = nullptr) const;
  // Property metadata (interpolation, elementSize ...) from the strongest spec that has it.
  const Value* property_meta(std::string_view name, std::string_view key) const;
  // Prim metadata (kind, instanceable ...) from the strongest spec that has it.
  const Value* meta(std::string_view key) const;
  // Composed relationship targets / attribute connections, translated to stage paths.
  std::vector<std::string> targets(std::string_view relationship) const;
  std::vector<std::string> connections(std::string_view attribute) const;
  bool has_api(std::string_view schema) const;
};

struct StageLimits {
  int max_prims = 1 << 20;     // composed prims
  int max_index_nodes = 4096;  // specs contributing to one prim
  int max_arc_depth = 64;      // nested references / payloads / variants
  long max_total_nodes = 1L << 23;  // specs visited while composing the whole stage (bounds the work)
};

class Stage {
 public:
  // Opens the root layer and composes everything it reaches. Errors: the first layer that cannot be read
  // or parsed, a reference without a target prim, a cycle of arcs (a prim that references itself); a
  // reference to a prim that does not exist and a cycle of subLayers are warnings (USD tolerates them).
  static Expected<std::unique_ptr<Stage>> open(const std::string& path, const StageLimits& limits = {});

  const Prim& root() const { return root_; }
  const Prim* prim_at(std::string_view path) const;
  const Layer& root_layer() const { return *root_layer_; }
  const std::vector<std::string>& warnings() const { return warnings_; }
  std::size_t layer_count() const { return layers_.size(); }
  // The file of every layer the stage read (root layer, sublayers, referenced and payload layers).
  std::vector<std::string> layer_paths() const {
    std::vector<std::string> paths;
    for (const auto& [path, layer] : layers_) paths.push_back(path);
    return paths;
  }

  // Stage metadata (root layer) with USD's fallbacks.
  double start_time_code() const;
  double end_time_code() const;
  double time_codes_per_second() const;
  double frames_per_second() const;
  std::string up_axis() const;
  double meters_per_unit() const;

 private:
  friend class Composer;
  Prim root_;
  std::string root_layer_path_;
  const Layer* root_layer_ = nullptr;
  std::map<std::string, std::unique_ptr<Layer>> layers_;
  std::vector<std::string> warnings_;
};

}  // namespace temporal::usd
