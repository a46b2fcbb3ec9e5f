#include "temporal/core/method.h"

#include <algorithm>

namespace temporal {

MethodOptionSet::MethodOptionSet(const MethodOptionSet& other) { *this = other; }
MethodOptionSet& MethodOptionSet::operator=(const MethodOptionSet& other) {
  if (this == &other) return *this;
  entries_.clear();
  for (const auto& [name, options] : other.entries_) entries_.emplace_back(name, options->clone());
  return *this;
}
MethodOptionSet::~MethodOptionSet() = default;

void MethodOptionSet::add(std::string name, std::unique_ptr<MethodOptions> options) {
  entries_.emplace_back(std::move(name), std::move(options));
}

MethodOptions* MethodOptionSet::find(std::string_view name) {
  for (auto& [n, options] : entries_)
    if (n == name) return options.get();
  return nullptr;
}
const MethodOptions* MethodOptionSet::find(std::string_view name) const {
  return const_cast<MethodOptionSet*>(this)->find(name);
}

Status check_device(std::string_view method, std::string_view device, const std::vector<std::string>& devices) {
  const std::vector<std::string>& known = device_names();
  if (std::find(known.begin(), known.end(), device) == known.end()) return not_one_of("--device", device, known);
  if (std::find(devices.begin(), devices.end(), device) != devices.end()) return Status::ok();
  std::string have;
  for (const auto& d : devices) have += (have.empty() ? "" : ", ") + d;
  return Error::usage("--method " + std::string(method) + " has no " + std::string(device) +
                      " implementation (it runs on: " + have + "): pass --device " +
                      (devices.empty() ? std::string(kCpuDevice) : devices.front()) + " or another --method");
}

}  // namespace temporal
