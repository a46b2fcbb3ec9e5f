// The methods of a stage as units, one pattern for every stage (upsample-st's methods, filter-phlm's filters,
// morph-120hz's methods). A method's source file defines its registry entry: what it is (MethodInfo), its own
// parameters (an options struct with defaults and `ParamList params()`, wrapped by OptionsOf), the G-buffer
// layers it reads, and its implementations (one per device: "cpu", and "gpu" where a GLSL kernel exists). The
// stage's registry.cpp lists the entries, one line each. Everything else is derived from that list: the --method
// choices and --help, each method's options inside the stage's options (MethodOptionSet), --list-methods and
// --list-methods-json, the variants the benchmarks and tests run, the layers read. A stage's entry type starts
// with the three members the helpers below read:
//   struct MethodEntry {
//     MethodInfo info;
//     std::unique_ptr<MethodOptions> (*make_options)() = nullptr;  // nullptr: no parameters of its own
//     std::vector<LayerNeed> (*layers)(const StageOptions&) = nullptr;
//     std::vector<Implementation<Factory>> implementations = {};  // Factory: a DeviceFactory<...>
//     ...  // what only that stage needs
//   };
// and each stage offers registry(), find_entry(name) (nullptr when unknown), method_variants(), find_variant().
#pragma once

#include "temporal/core/error.h"
#include "temporal/core/params.h"
#include "temporal/core/suggest.h"

#include <memory>
#include <optional>
#include <string>
#include <type_traits>
#include <string_view>
#include <utility>
#include <vector>

namespace temporal {

namespace gpu {
class Context;  // temporal/gpu/context.h (the gpu stage); core only passes it through
}  // namespace gpu

// The device of the implementations every method has.
inline constexpr const char* kCpuDevice = "cpu";
// The device of the GLSL compute kernels (the gpu stage, docs/gpu.md): a hardware GPU through EGL, or llvmpipe.
inline constexpr const char* kGpuDevice = "gpu";
// The devices `--device` accepts, in the order --help lists them.
inline const std::vector<std::string>& device_names() {
  static const std::vector<std::string> names = {kCpuDevice, kGpuDevice};
  return names;
}
// The --device parameter of every method tool, bound to `device` (check_method_device says whether the chosen
// method has an implementation there).
inline Param device_param(std::string* device) {
  return Param::choice("--device",
                       "Where the method runs: cpu (the C++ reference) or gpu (its GLSL compute kernel through EGL; "
                       "--list-methods says which methods have one)",
                       device, device_names());
}

// A named way to run a method: the method and the arguments that select the variant, written as on the command
// line ("herzog-lagged" = --method herzog --lagged-wf).
struct MethodVariant {
  std::string name;
  std::string method;
  std::vector<std::string> args;
  std::string summary;
};

// What a method is, as --help and --list-methods say it.
struct MethodInfo {
  std::string name;                     // --method NAME, `temporal:method`
  std::string summary;                  // one line, with the paper and its equations
  bool has_state = false;               // keeps anything between frames (--state-in / --state-out)
  std::vector<MethodVariant> variants = {};  // named variants besides the defaults
  // Stages with the notion (morph): rendered frames of display latency the method adds.
  std::optional<int> latency_frames = std::nullopt;
  // (Every member has a default initializer: entries name only what they set, and GCC's
  // -Wmissing-field-initializers stays quiet about the rest.)
};

// One implementation of a method: the device it runs on and its factory (the stage's type: a filter, a state).
template <typename Factory>
struct Implementation {
  const char* device;
  Factory make;
};

// The factory of a stage's implementations: one type for both kinds of factory a method's source file has, so
// that an entry lists them side by side, `{kCpuDevice, cpu_lambda}, {kGpuDevice, make_NAME_gpu}`:
//  - a CPU factory, `std::unique_ptr<Product> (Args...)` (a captureless lambda or a function): cannot fail;
//  - a GPU factory, `Expected<std::unique_ptr<Product>> (std::shared_ptr<gpu::Context>, Args...)`: the form of
//    the gpu kernels' factories (docs/gpu.md), which fail with the driver's message.
// Called with the run's GPU context (null on the CPU), it returns the product or the GPU factory's error.
template <typename Product, typename... Args>
class DeviceFactory {
 public:
  using Cpu = std::unique_ptr<Product> (*)(Args...);
  using Gpu = Expected<std::unique_ptr<Product>> (*)(std::shared_ptr<gpu::Context>, Args...);

  template <typename F>
    requires(std::is_convertible_v<F, Cpu> || std::is_convertible_v<F, Gpu>)
  DeviceFactory(F f) {  // NOLINT: implicit by design, `{kGpuDevice, make_NAME_gpu}`
    if constexpr (std::is_convertible_v<F, Cpu>)
      cpu_ = f;
    else
      gpu_ = f;
  }

  Expected<std::unique_ptr<Product>> operator()(std::shared_ptr<gpu::Context> context, Args... args) const {
    if (cpu_) return cpu_(std::forward<Args>(args)...);
    return gpu_(std::move(context), std::forward<Args>(args)...);
  }
  // A CPU factory called directly (the tests and benchmarks that run the C++ reference); null for a GPU factory.
  std::unique_ptr<Product> operator()(Args... args) const {
    return cpu_ ? cpu_(std::forward<Args>(args)...) : nullptr;
  }
  // Whether it needs a GPU context (a GPU factory).
  bool needs_gpu() const { return gpu_ != nullptr; }

 private:
  Cpu cpu_ = nullptr;
  Gpu gpu_ = nullptr;
};

// A method's own parameters: an options struct defined in the method's source file (its fields hold the defaults)
// that lists them as Params pointing at those fields. A stage's options hold one per registered method
// (MethodOptionSet), so that the command line binds every method's flags before the method is chosen.
class MethodOptions {
 public:
  virtual ~MethodOptions() = default;
  virtual std::unique_ptr<MethodOptions> clone() const = 0;
  virtual ParamList params() = 0;
  // Checks that a range cannot express (e.g. a power of two); the ranges themselves are checked by the Params.
  virtual Status check() const { return Status::ok(); }
};

// A method's options struct T (fields with defaults, `ParamList params()`, optionally `Status check() const`) as
// MethodOptions.
template <typename T>
class OptionsOf : public MethodOptions, public T {
 public:
  std::unique_ptr<MethodOptions> clone() const override { return std::make_unique<OptionsOf>(*this); }
  ParamList params() override { return T::params(); }
  Status check() const override {
    if constexpr (requires(const T& t) { t.check(); })
      return T::check();
    else
      return Status::ok();
  }
  static std::unique_ptr<MethodOptions> make() { return std::make_unique<OptionsOf>(); }
};

// The options of every method of a stage that has parameters, by method name; copied deeply.
class MethodOptionSet {
 public:
  MethodOptionSet() = default;
  MethodOptionSet(const MethodOptionSet& other);
  MethodOptionSet& operator=(const MethodOptionSet& other);
  MethodOptionSet(MethodOptionSet&&) noexcept = default;
  MethodOptionSet& operator=(MethodOptionSet&&) noexcept = default;
  ~MethodOptionSet();
  void add(std::string name, std::unique_ptr<MethodOptions> options);
  // The options of method `name` (nullptr for a method without parameters or an unknown name).
  MethodOptions* find(std::string_view name);
  const MethodOptions* find(std::string_view name) const;

 private:
  std::vector<std::pair<std::string, std::unique_ptr<MethodOptions>>> entries_;
};

// The typed view of method `name`'s options T in `set` (T's defaults when the set has none).
template <typename T>
const T& method_options(const MethodOptionSet& set, std::string_view name) {
  static const OptionsOf<T> defaults;
  const MethodOptions* m = set.find(name);
  return m ? static_cast<const OptionsOf<T>&>(*m) : defaults;
}

// --- Helpers every stage's registry.cpp uses on its table (a vector of `const Entry*`) ------------------------

// A stage's table is an X-macro list, one line per method: `X(name)` stands for `const MethodEntry&
// name_method()`, defined in the method's source file. These two expand a list into the declarations and into the
// table's initialiser, so that a new method is one line in the list (compare's metrics do the same).
#define TEMPORAL_DECLARE_METHOD(name) const MethodEntry& name##_method();
#define TEMPORAL_METHOD_ADDRESS(name) &name##_method(),

// Defines, from a stage's X-macro list LIST, the registry functions its header declares: registry(),
// find_entry(name), method_variants(), find_variant(name) and default_method_options() (the helpers below on the
// table). One line in the stage's registry file, so that the three stages cannot drift apart.
#define TEMPORAL_DEFINE_REGISTRY(LIST)                                                                  \
  LIST(TEMPORAL_DECLARE_METHOD)                                                                         \
  const std::vector<const MethodEntry*>& registry() {                                                   \
    static const std::vector<const MethodEntry*> table = {LIST(TEMPORAL_METHOD_ADDRESS)};               \
    return table;                                                                                       \
  }                                                                                                     \
  const MethodEntry* find_entry(std::string_view name) { return find_entry_in(registry(), name); }       \
  const std::vector<MethodVariant>& method_variants() {                                                 \
    static const std::vector<MethodVariant> list = method_variants_of(registry());                      \
    return list;                                                                                        \
  }                                                                                                     \
  const MethodVariant* find_variant(std::string_view name) { return find_variant_in(method_variants(), name); } \
  MethodOptionSet default_method_options() { return method_option_set(registry()); }

template <typename Variant>
const Variant* find_variant_in(const std::vector<Variant>& variants, std::string_view name) {
  for (const Variant& v : variants)
    if (v.name == name) return &v;
  return nullptr;
}

// Options of a stage for `method`, with parameters set by command-line style arguments (the stage's params() and
// check()); usage error for an unknown method or parameter, or an invalid value.
template <typename Options>
Expected<Options> make_options_with(const std::string& method, const std::vector<std::string>& args,
                                    ParamList (*params)(Options&), Status (*check)(const Options&)) {
  Options o;
  o.method = method;
  if (Status s = apply_args(params(o), args); !s) return s.error();
  if (Status s = check(o); !s) return s.error();
  return o;
}

template <typename Entry>
const Entry* find_entry_in(const std::vector<const Entry*>& registry, std::string_view name) {
  for (const Entry* e : registry)
    if (e->info.name == name) return e;
  return nullptr;
}

template <typename Entry>
std::vector<std::string> method_names(const std::vector<const Entry*>& registry) {
  std::vector<std::string> names;
  for (const Entry* e : registry) names.push_back(e->info.name);
  return names;
}

// Usage error for `--method name` unless the registry has it (not_one_of's wording, with its suggestion).
template <typename Entry>
Status check_method_name(const std::vector<const Entry*>& registry, std::string_view name) {
  if (find_entry_in(registry, name)) return Status::ok();
  return not_one_of("--method", name, method_names(registry));
}

// Every method with its defaults (named after the method, no arguments) followed by its named variants, in
// table order: what --list-methods prints and the benchmarks and tests run.
template <typename Entry>
std::vector<MethodVariant> method_variants_of(const std::vector<const Entry*>& registry) {
  std::vector<MethodVariant> v;
  for (const Entry* e : registry) {
    v.push_back({e->info.name, e->info.name, {}, e->info.summary});
    v.insert(v.end(), e->info.variants.begin(), e->info.variants.end());
  }
  return v;
}

// The options of every method with parameters, with their defaults.
template <typename Entry>
MethodOptionSet method_option_set(const std::vector<const Entry*>& registry) {
  MethodOptionSet set;
  for (const Entry* e : registry)
    if (e->make_options) set.add(e->info.name, e->make_options());
  return set;
}

// Each method's own parameters, bound to `set`, in a --help section named after the method (Param::group).
template <typename Entry>
ParamList method_params(const std::vector<const Entry*>& registry, MethodOptionSet& set) {
  ParamList list;
  for (const Entry* e : registry)
    if (MethodOptions* m = set.find(e->info.name))
      for (Param p : m->params()) {
        if (p.group.empty()) p.group = e->info.name;
        list.push_back(std::move(p));
      }
  return list;
}

// The ranges of every method's parameters, then each method's own check().
template <typename Entry>
Status check_method_options(const std::vector<const Entry*>& registry, const MethodOptionSet& set) {
  MethodOptionSet copy = set;  // params() points at the fields it is given
  if (Status s = check_params(method_params(registry, copy)); !s) return s;
  for (const Entry* e : registry)
    if (const MethodOptions* m = set.find(e->info.name))
      if (Status s = m->check(); !s) return s;
  return Status::ok();
}

// The implementation of `entry` for `device`, or nullptr.
template <typename Entry>
auto find_implementation(const Entry& entry, std::string_view device) -> decltype(&entry.implementations.front()) {
  for (const auto& i : entry.implementations)
    if (device == i.device) return &i;
  return nullptr;
}

// The devices `entry` has an implementation for, in its order ({"cpu"}, {"cpu", "gpu"}).
template <typename Entry>
std::vector<std::string> implementation_devices(const Entry& entry) {
  std::vector<std::string> devices;
  for (const auto& i : entry.implementations) devices.emplace_back(i.device);
  return devices;
}

// Usage error unless `device` is one of device_names() and `entry` has an implementation on it; the message
// names the devices the method has.
Status check_device(std::string_view method, std::string_view device, const std::vector<std::string>& devices);
template <typename Entry>
Status check_method_device(const Entry& entry, std::string_view device) {
  return check_device(entry.info.name, device, implementation_devices(entry));
}

// The check() of a stage whose options are all Params (upsample-st's, filter-phlm's): --method is registered,
// the stage's own parameters (`params`, the stage's params()) are in range, the method has an implementation on
// --device, then each method's own parameters. Usage error naming the first that fails.
template <typename Entry, typename Options>
Status check_stage_options(const std::vector<const Entry*>& registry, const Options& options,
                           ParamList (*params)(std::type_identity_t<Options>&)) {
  if (Status s = check_method_name(registry, options.method); !s) return s;
  Options copy = options;  // params() points at the fields it is given
  if (Status s = check_params(params(copy)); !s) return s;
  if (Status s = check_method_device(*find_entry_in(registry, options.method), options.device); !s) return s;
  return check_method_options(registry, options.per_method);
}

}  // namespace temporal
