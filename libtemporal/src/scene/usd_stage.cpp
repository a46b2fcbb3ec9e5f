// USD composition (usd_stage.h): a prim index is a tree of nodes, one per contributing site; a node's
// children are the arcs authored on its spec, ordered inherits, variants, references, payloads, specializes;
// the strength order of the sites is the tree's pre-order. A child prim's index mirrors its parent's tree
// (ancestral arcs keep contributing below the prim that introduced them) and adds the arcs authored on the
// child's own specs. Variant selections are looked up over the whole index, strongest first, after the
// other arcs have been expanded, one variant set at a time.
#include "usd_stage.h"

#include <algorithm>
#include <functional>

namespace temporal::usd {

namespace {

bool has_prefix(const std::string& path, const std::string& prefix) {
  if (path == prefix) return true;
  return path.size() > prefix.size() && path.compare(0, prefix.size(), prefix) == 0 &&
         (path[prefix.size()] == '/' || path[prefix.size()] == '.');
}

}  // namespace

std::optional<std::string> PathMap::translate(const std::string& path) const {
  std::string p = path;
  for (const PathMap* m = this; m; m = m->outer.get()) {
    if (m->from == "/") {
      if (m->to != "/") p = m->to + p;
    } else if (has_prefix(p, m->from)) {
      p = m->to + p.substr(m->from.size());
    } else {
      return std::nullopt;
    }
  }
  return p;
}

const Prim* Prim::child(std::string_view n) const {
  for (const auto& c : children)
    if (c->name == n) return c.get();
  return nullptr;
}

const PropertySpec* Prim::property(std::string_view n, const Site** site) const {
  for (const Site& s : sites) {
    if (const PropertySpec* p = s.spec->property(n)) {
      if (site) *site = &s;
      return p;
    }
  }
  return nullptr;
}

const PropertySpec* Prim::attribute(std::string_view n, const Site** site) const {
  for (const Site& s : sites) {
    const PropertySpec* p = s.spec->property(n);
    if (!p) continue;
    // Time samples win over a default of the same spec (USD value resolution); a None default blocks.
    if (!p->time_samples.empty() || p->has_default) {
      if (p->time_samples.empty() && p->default_value.is_none()) return nullptr;
      if (site) *site = &s;
      return p;
    }
  }
  return nullptr;
}

const Value* Prim::property_meta(std::string_view n, std::string_view key) const {
  for (const Site& s : sites) {
    const PropertySpec* p = s.spec->property(n);
    if (!p) continue;
    for (const auto& [k, v] : p->metadata)
      if (k == key) return &v;
  }
  return nullptr;
}

const Value* Prim::meta(std::string_view key) const {
  for (const Site& s : sites)
    if (const Value* v = s.spec->meta(key)) return v;
  return nullptr;
}

namespace {

// Composes a list op over sites from weakest to strongest, translating each site's paths.
std::vector<std::string> compose_paths(const std::vector<Site>& sites, std::string_view name,
                                       const ListOp<std::string> PropertySpec::*member) {
  std::vector<std::string> result;
  for (auto it = sites.rbegin(); it != sites.rend(); ++it) {
    const PropertySpec* p = it->spec->property(name);
    if (!p) continue;
    const ListOp<std::string>& op = p->*member;
    if (op.empty()) continue;
    auto translated = [&](const std::vector<std::string>& in) {
      std::vector<std::string> out;
      for (const auto& t : in) {
        if (auto m = it->map->translate(t)) out.push_back(*m);
      }
      return out;
    };
    if (op.is_explicit) {
      result = translated(op.explicit_items);
      continue;
    }
    for (const auto& d : translated(op.deleted)) result.erase(std::remove(result.begin(), result.end(), d), result.end());
    const auto pre = translated(op.prepended);
    for (const auto& x : pre) result.erase(std::remove(result.begin(), result.end(), x), result.end());
    result.insert(result.begin(), pre.begin(), pre.end());
    for (const auto& x : translated(op.appended)) {
      if (std::find(result.begin(), result.end(), x) == result.end()) result.push_back(x);
    }
  }
  return result;
}

}  // namespace

std::vector<std::string> Prim::targets(std::string_view relationship) const {
  return compose_paths(sites, relationship, &PropertySpec::targets);
}

std::vector<std::string> Prim::connections(std::string_view attribute) const {
  return compose_paths(sites, attribute, &PropertySpec::connections);
}

bool Prim::has_api(std::string_view schema) const {
  for (const Site& s : sites) {
    const auto& op = s.spec->api_schemas;
    for (const auto* list : {&op.explicit_items, &op.prepended, &op.appended})
      if (std::find(list->begin(), list->end(), schema) != list->end()) return true;
  }
  return false;
}

const Prim* Stage::prim_at(std::string_view path) const { return descend_path(&root_, path); }

double Stage::start_time_code() const { return root_layer_->number("startTimeCode", 0.0); }
double Stage::end_time_code() const { return root_layer_->number("endTimeCode", start_time_code()); }
double Stage::time_codes_per_second() const {
  const double fps = root_layer_->number("framesPerSecond", 24.0);
  const double t = root_layer_->number("timeCodesPerSecond", fps);
  return t > 0.0 ? t : 24.0;
}
double Stage::frames_per_second() const {
  const double f = root_layer_->number("framesPerSecond", time_codes_per_second());
  return f > 0.0 ? f : time_codes_per_second();
}
std::string Stage::up_axis() const { return root_layer_->token("upAxis", "Y"); }
double Stage::meters_per_unit() const { return root_layer_->number("metersPerUnit", 0.01); }

// ---- composition --------------------------------------------------------------------------------------------

namespace compose_detail {

enum class Arc : std::uint8_t { Root, Inherit, Variant, Reference, Payload, Specialize };

struct LayerStack {
  std::vector<std::pair<const Layer*, LayerOffset>> layers;  // strongest first
};

struct Node {
  Arc arc = Arc::Root;
  bool ancestral = false;
  const Layer* layer = nullptr;
  std::string path;
  const PrimSpec* spec = nullptr;
  std::shared_ptr<const PathMap> map;
  LayerOffset offset;
  std::shared_ptr<const LayerStack> stack;
  int depth = 0;
  std::vector<std::string> variant_sets_done;
  std::vector<std::unique_ptr<Node>> children;
  const Node* parent = nullptr;
};

using Index = std::vector<std::unique_ptr<Node>>;

}  // namespace compose_detail

using compose_detail::Arc;
using compose_detail::Index;
using compose_detail::LayerStack;
using compose_detail::Node;

namespace {

LayerOffset compose(const LayerOffset& outer, const LayerOffset& inner) {
  return {outer.offset + outer.scale * inner.offset, outer.scale * inner.scale};
}

double layer_tcps(const Layer& l) {
  const double fps = l.number("framesPerSecond", 24.0);
  const double t = l.number("timeCodesPerSecond", fps);
  return t > 0.0 ? t : 24.0;
}

std::string position(const Layer& layer, int line, int column) {
  return layer.path + ":" + std::to_string(line) + ":" + std::to_string(column);
}

template <typename T>
std::vector<T> items(const ListOp<T>& op) {
  if (op.is_explicit) return op.explicit_items;
  std::vector<T> out = op.prepended;
  out.insert(out.end(), op.appended.begin(), op.appended.end());
  return out;
}

void for_each_node(Index& index, const std::function<bool(Node&)>& f);

bool visit(Node& n, const std::function<bool(Node&)>& f) {
  if (!f(n)) return false;
  for (auto& c : n.children)
    if (!visit(*c, f)) return false;
  return true;
}

void for_each_node(Index& index, const std::function<bool(Node&)>& f) {
  for (auto& n : index)
    if (!visit(*n, f)) return;
}

}  // namespace

class Composer {
 public:
  Composer(Stage& stage, const StageLimits& limits) : stage_(stage), limits_(limits) {}

  Expected<const Layer*> layer(const std::string& path, const std::string& where) {
    auto found = stage_.layers_.find(path);
    if (found != stage_.layers_.end()) return found->second.get();
    auto parsed = read_usda(path);
    if (!parsed) {
      if (where.empty()) return parsed.error();
      Error e = parsed.error();
      if (e.file == path) {  // the layer itself could not be opened (not a parse error inside it)
        return Error::input(where, "cannot use the layer @" + path + "@: " + e.message);
      }
      return e;
    }
    const Layer* l = parsed->get();
    stage_.layers_.emplace(path, std::move(*parsed));
    return l;
  }

  // A layer and its sublayers, strongest first, each with its time offset (and the scaling between
  // different timeCodesPerSecond).
  Expected<std::shared_ptr<const LayerStack>> stack_of(const Layer* root) {
    auto cached = stacks_.find(root);
    if (cached != stacks_.end()) return cached->second;
    auto stack = std::make_shared<LayerStack>();
    std::vector<const Layer*> chain;
    if (Status s = add_to_stack(*stack, root, LayerOffset{}, chain); !s) return s.error();
    stacks_[root] = stack;
    return std::shared_ptr<const LayerStack>(stack);
  }

  Status compose_stage() {
    auto root = layer(stage_.root_layer_path_, "");
    if (!root) return root.error();
    stage_.root_layer_ = *root;
    auto stack = stack_of(*root);
    if (!stack) return stack.error();
    root_stack_ = *stack;
    Prim& pseudo = stage_.root_;
    pseudo.name = "";
    pseudo.path = "/";
    pseudo.specifier = Specifier::Def;
    // Root prims: the union of the root prims of the root layer stack.
    std::vector<std::string> names;
    for (const auto& [l, off] : root_stack_->layers)
      for (const auto& c : l->root.children)
        if (std::find(names.begin(), names.end(), c->name) == names.end()) names.push_back(c->name);
    for (const std::string& name : names) {
      Index index;
      for (const auto& [l, off] : root_stack_->layers) {
        auto n = std::make_unique<Node>();
        n->layer = l;
        n->path = "/" + name;
        n->spec = l->root.child(name);
        n->map = identity_;
        n->offset = off;
        n->stack = root_stack_;
        index.push_back(std::move(n));
      }
      if (Status s = compose_prim(pseudo, name, std::move(index)); !s) return s;
    }
    return {};
  }

 private:
  Status add_to_stack(LayerStack& stack, const Layer* l, LayerOffset off, std::vector<const Layer*>& chain) {
    if (std::find(chain.begin(), chain.end(), l) != chain.end()) {
      stage_.warnings_.push_back(l->path + ": subLayers form a cycle; the repeated layer is skipped");
      return {};
    }
    if (chain.size() > 32) return Error::input(l->path, "subLayers nested more than 32 deep");
    stack.layers.emplace_back(l, off);
    chain.push_back(l);
    for (const SubLayer& sub : l->sublayers) {
      auto s = layer(sub.resolved, position(*l, sub.line, sub.column));
      if (!s) return s.error();
      LayerOffset so = sub.offset;
      so.scale *= layer_tcps(*l) / layer_tcps(**s);
      if (Status st = add_to_stack(stack, *s, compose(off, so), chain); !st) return st;
    }
    chain.pop_back();
    return {};
  }

  // Inserts `n` among `parent`'s children by arc strength; direct arcs before ancestral ones of one kind.
  static Node* adopt(Node& parent, std::unique_ptr<Node> n) {
    n->parent = &parent;
    auto pos = std::find_if(parent.children.begin(), parent.children.end(), [&](const std::unique_ptr<Node>& c) {
      return c->arc > n->arc || (c->arc == n->arc && c->ancestral && !n->ancestral);
    });
    return parent.children.insert(pos, std::move(n))->get();
  }

  // Whether an arc to `path` in layer `l` comes back to a site of the chain above `n`: the same prim, or an
  // ancestor of it (whose namespace holds the arc again, so composing it would never end).
  static bool in_chain(const Node& n, const Layer* l, const std::string& path) {
    for (const Node* p = &n; p; p = p->parent)
      if (p->layer == l && (p->path == path || (p->path.size() > path.size() && p->path.compare(0, path.size(), path) == 0 &&
                                                (path == "/" || p->path[path.size()] == '/'))))
        return true;
    return false;
  }

  // Adds the sites of prim `target` in `stack` below `n` (an arc of kind `arc`) and expands them.
  Status add_arc(Node& n, Arc arc, const std::shared_ptr<const LayerStack>& stack, const std::string& target,
                 const LayerOffset& arc_offset, const std::string& where) {
    if (n.depth >= limits_.max_arc_depth) {
      return Error::input(where, "composition arcs nested more than " + std::to_string(limits_.max_arc_depth) + " deep");
    }
    bool found = false;
    for (const auto& [l, off] : stack->layers) {
      // OpenUSD reports an arc cycle as a composition error and drops the arc; a scene whose prim references
      // itself (or an arc chain that comes back to it) is malformed, and rendering it without that arc would
      // draw something else than its author meant: an Input error naming the prim (issue 26).
      if (in_chain(n, l, target)) {
        return Error::input(where, "the arc to <" + target + "> in " + l->path + " forms a cycle (prim " + n.path +
                                       " references itself or an ancestor, directly or through other arcs)");
      }
      auto child = std::make_unique<Node>();
      child->arc = arc;
      child->layer = l;
      child->path = target;
      child->spec = l->prim_at(target);
      found = found || child->spec;
      auto map = std::make_shared<PathMap>();
      map->from = target;
      map->to = n.path;
      map->outer = n.map;
      child->map = std::move(map);
      child->offset = compose(compose(n.offset, arc_offset), off);
      child->stack = stack;
      child->depth = n.depth + 1;
      Node* added = adopt(n, std::move(child));
      if (Status s = count_node(where); !s) return s;
      if (Status s = expand(*added); !s) return s;
    }
    if (!found && arc != Arc::Inherit && arc != Arc::Specialize) {
      stage_.warnings_.push_back(where + ": the arc names <" + target + ">, which no layer of " +
                                 stack->layers.front().first->path + " defines: it contributes nothing");
    }
    return {};
  }

  Status count_node(const std::string& where) {
    if (++index_nodes_ > limits_.max_index_nodes)
      return Error::input(where, "more than " + std::to_string(limits_.max_index_nodes) + " specs contribute to one prim");
    return count_work(where, 1);
  }

  Status count_work(const std::string& where, long nodes) {
    total_nodes_ += nodes;
    if (total_nodes_ > limits_.max_total_nodes)
      return Error::input(where, "composing the stage visits more than " + std::to_string(limits_.max_total_nodes) +
                                     " specs (arcs that multiply each other?)");
    return {};
  }

  Status reference_arcs(Node& n, const ListOp<Reference>& op, Arc arc) {
    for (const Reference& r : items(op)) {
      const std::string where = position(*n.layer, r.line, r.column);
      std::shared_ptr<const LayerStack> stack = n.stack;
      std::string target = r.prim;
      LayerOffset off = r.offset;
      if (!r.asset.empty()) {
        auto l = layer(r.resolved, where);
        if (!l) return l.error();
        auto s = stack_of(*l);
        if (!s) return s.error();
        stack = *s;
        off.scale *= layer_tcps(*n.layer) / layer_tcps(**l);
        if (target.empty()) target = (*l)->default_prim.empty() ? "" : "/" + (*l)->default_prim;
        if (target.empty()) {
          return Error::input(where, "the reference to @" + r.asset + "@ names no prim and that layer has no defaultPrim; "
                                     "name the prim (@" + r.asset + "@</Prim>)");
        }
      } else if (target.empty()) {
        return Error::input(where, "an internal reference needs a prim path (</Prim>)");
      }
      if (Status s = add_arc(n, arc, stack, target, off, where); !s) return s;
    }
    return {};
  }

  // The arcs authored on n's spec, except variants (resolved once the whole index is known).
  Status expand(Node& n) {
    if (!n.spec) return {};
    const std::string where = position(*n.layer, n.spec->line, n.spec->column);
    for (const std::string& c : items(n.spec->inherits))
      if (Status s = add_arc(n, Arc::Inherit, n.stack, c, {}, where); !s) return s;
    if (Status s = reference_arcs(n, n.spec->references, Arc::Reference); !s) return s;
    if (Status s = reference_arcs(n, n.spec->payloads, Arc::Payload); !s) return s;
    for (const std::string& c : items(n.spec->specializes))
      if (Status s = add_arc(n, Arc::Specialize, n.stack, c, {}, where); !s) return s;
    return {};
  }

  // The selection of variant set `set`: the strongest authored one over the whole index.
  static const std::string* selection(Index& index, const std::string& set) {
    const std::string* found = nullptr;
    for_each_node(index, [&](Node& n) {
      if (n.spec) found = n.spec->variant_selection(set);
      return found == nullptr;
    });
    return found;
  }

  // Applies variant sets one at a time, strongest first, until none is left.
  Status resolve_variants(Index& index) {
    while (true) {
      Node* target = nullptr;
      std::string set;
      for_each_node(index, [&](Node& n) {
        if (!n.spec) return true;
        for (const std::string& name : items(n.spec->variant_set_names)) {
          if (std::find(n.variant_sets_done.begin(), n.variant_sets_done.end(), name) != n.variant_sets_done.end()) continue;
          target = &n;
          set = name;
          return false;
        }
        return true;
      });
      if (!target) return {};
      target->variant_sets_done.push_back(set);
      const std::string* sel = selection(index, set);
      const VariantSetSpec* vs = target->spec->variant_set(set);
      const PrimSpec* variant = sel && vs ? vs->find(*sel) : nullptr;
      if (!variant) continue;
      const std::string where = position(*target->layer, variant->line, variant->column);
      if (target->depth >= limits_.max_arc_depth) return Error::input(where, "variants nested too deeply");
      auto child = std::make_unique<Node>();
      child->arc = Arc::Variant;
      child->layer = target->layer;
      child->path = target->path;
      child->spec = variant;
      child->map = target->map;
      child->offset = target->offset;
      child->stack = target->stack;
      child->depth = target->depth + 1;
      Node* added = adopt(*target, std::move(child));
      if (Status s = count_node(where); !s) return s;
      if (Status s = expand(*added); !s) return s;
    }
  }

  // The index of child `name`: every node of the parent's index continued one level down.
  static std::unique_ptr<Node> mirror(const Node& n, const std::string& name) {
    auto m = std::make_unique<Node>();
    m->arc = n.arc;
    m->ancestral = n.arc != Arc::Root;
    m->layer = n.layer;
    m->path = n.path == "/" ? "/" + name : n.path + "/" + name;
    m->spec = n.spec ? n.spec->child(name) : nullptr;
    m->map = n.map;
    m->offset = n.offset;
    m->stack = n.stack;
    m->depth = n.depth;
    for (const auto& c : n.children) {
      auto mc = mirror(*c, name);
      if (!mc->spec && mc->children.empty()) continue;  // contributes nothing below
      mc->parent = m.get();
      m->children.push_back(std::move(mc));
    }
    return m;
  }

  Status compose_prim(Prim& parent, const std::string& name, Index index) {
    if (++prim_count_ > limits_.max_prims)
      return Error::input(stage_.root_layer_->path, "the stage has more than " + std::to_string(limits_.max_prims) + " prims");
    index_nodes_ = 0;
    for_each_node(index, [&](Node&) { ++index_nodes_; return true; });
    if (Status s = count_work(stage_.root_layer_->path, index_nodes_); !s) return s;
    // Direct arcs of this prim's specs (the mirrored nodes' own specs), then its variants.
    std::vector<Node*> with_spec;
    for_each_node(index, [&](Node& n) {
      if (n.spec) with_spec.push_back(&n);
      return true;
    });
    for (Node* n : with_spec)
      if (Status s = expand(*n); !s) return s;
    if (Status s = resolve_variants(index); !s) return s;

    auto prim = std::make_unique<Prim>();
    prim->name = name;
    prim->path = parent.path == "/" ? "/" + name : parent.path + "/" + name;
    prim->parent = &parent;
    for_each_node(index, [&](Node& n) {
      if (n.spec) prim->sites.push_back({n.layer, n.spec, n.map, n.offset});
      return true;
    });
    if (prim->sites.empty()) return {};  // nothing authored anywhere (an arc to a missing prim)
    summarise(*prim, parent);
    Prim& p = *prim;
    parent.children.push_back(std::move(prim));
    if (!p.active) return {};
    std::vector<std::string> names;
    for (const Site& s : p.sites)
      for (const auto& c : s.spec->children)
        if (std::find(names.begin(), names.end(), c->name) == names.end()) names.push_back(c->name);
    for (const std::string& child : names) {
      Index ci;
      for (const auto& n : index) {
        auto m = mirror(*n, child);
        m->ancestral = false;
        if (m->spec || !m->children.empty()) ci.push_back(std::move(m));
      }
      if (Status s = compose_prim(p, child, std::move(ci)); !s) return s;
    }
    return {};
  }

  static void summarise(Prim& p, const Prim& parent) {
    bool have_spec = false;
    for (const Site& s : p.sites) {
      if (p.type_name.empty()) p.type_name = s.spec->type_name;
      if (!have_spec && s.spec->specifier != Specifier::Over) {
        p.specifier = s.spec->specifier;
        have_spec = true;
      }
    }
    if (const Value* a = p.meta("active"); a && a->kind == Value::Kind::Number && a->numbers.size() == 1)
      p.active = a->numbers[0] != 0.0;
    p.abstract = parent.abstract || p.specifier == Specifier::Class;
  }

  Stage& stage_;
  StageLimits limits_;
  std::map<const Layer*, std::shared_ptr<const LayerStack>> stacks_;
  std::shared_ptr<const LayerStack> root_stack_;
  std::shared_ptr<const PathMap> identity_ = std::make_shared<PathMap>(PathMap{"/", "/", nullptr});
  int prim_count_ = 0;
  int index_nodes_ = 0;
  long total_nodes_ = 0;
};

Expected<std::unique_ptr<Stage>> Stage::open(const std::string& path, const StageLimits& limits) {
  auto stage = std::unique_ptr<Stage>(new Stage());
  stage->root_layer_path_ = path;
  Composer composer(*stage, limits);
  if (Status s = composer.compose_stage(); !s) return s.error();
  return stage;
}

}  // namespace temporal::usd
